// A record's field table: one row per field (its key, unit and where its value lives), from which
// the record's JSON is written and read and a job's results columns are declared. A field lives in
// a member of the record (the report of a bed, the scenario's structs: written and read back), or
// is read by a getter from a record that holds it elsewhere (a drop's DEM figures, job_reports.h:
// read from the trace and the engine's result the drop's record owns, never read back).
#pragma once
#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include <limits>
#include <optional>
#include <stdexcept>
#include <string>
#include <type_traits>
#include <vector>

namespace gravsweep::results {

/// A number a record did not get (a file of an older build): NaN, null in JSON.
inline constexpr double kNotRecorded = std::numeric_limits<double>::quiet_NaN();

/// Where one value of type T of record R lives: a member (read and written) or a getter (read
/// only). Made from either, so that a table row names the one it has: `.count = &B::steps` or
/// `.count = [](const D& d) { ... }`. Empty (false) when the row has no value of this type.
template <class R, class T>
struct FieldAccess {
  T R::*member = nullptr;
  T (*getter)(const R&) = nullptr;
  FieldAccess() = default;
  FieldAccess(T R::*m) : member(m) {}  // NOLINT(google-explicit-constructor): a table row's member
  /// A captureless lambda or a function (a table row's getter).
  template <class F, class = std::enable_if_t<std::is_convertible_v<F, T (*)(const R&)>>>
  FieldAccess(F f) : getter(static_cast<T (*)(const R&)>(f)) {}  // NOLINT(google-explicit-constructor)
  FieldAccess(std::nullptr_t) {}  // NOLINT(google-explicit-constructor): no value of this type
  explicit operator bool() const { return member || getter; }
  [[nodiscard]] T read(const R& r) const { return member ? r.*member : getter(r); }
};

/// One field of record R. Exactly one access is set: a number, a number that may be absent (JSON
/// null), a count, a flag or a text.
template <class R>
struct RecordField {
  const char* key;   ///< JSON key and results column (units in the name)
  const char* unit;  ///< SI unit; "1" for counts and flags, "" for text
  FieldAccess<R, double> number = nullptr;
  FieldAccess<R, std::optional<double>> maybe = nullptr;
  FieldAccess<R, long long> count = nullptr;
  FieldAccess<R, bool> flag = nullptr;
  FieldAccess<R, std::string> text = nullptr;
  /// Its column type where a job's results row holds it: REAL, INTEGER (counts, flags) or TEXT.
  [[nodiscard]] const char* sql_type() const { return number || maybe ? "REAL" : count || flag ? "INTEGER" : "TEXT"; }
};

/// Field f of r as a JSON value (an absent number as null).
template <class R>
nlohmann::json field_json(const R& r, const RecordField<R>& f) {
  if (f.number) return f.number.read(r);
  if (f.maybe) {
    const std::optional<double> v = f.maybe.read(r);
    return v ? nlohmann::json(*v) : nlohmann::json(nullptr);
  }
  if (f.count) return f.count.read(r);
  if (f.flag) return f.flag.read(r);
  return f.text.read(r);
}

/// Every field of r, in the table's order (an absent number as null).
template <class R>
nlohmann::json record_json(const R& r, const std::vector<RecordField<R>>& fields) {
  nlohmann::json j = nlohmann::json::object();
  for (const auto& f : fields) j[f.key] = field_json(r, f);
  return j;
}

/// The record from j. A key j lacks keeps its default (a file of an older build that did not
/// record it), a null number reads as kNotRecorded (JSON writes a NaN or an infinity as null); a
/// key of the wrong type is an error naming `where` and the key. Every field of the table lives in
/// a member (a getter's value is not a record's to be read back: std::logic_error).
template <class R>
R record_of_json(const nlohmann::json& j, const std::vector<RecordField<R>>& fields, const std::string& where) {
  if (!j.is_object())
    throw std::runtime_error(fmt::format("{}: expected a JSON object, found {}", where, j.type_name()));
  R r;
  for (const auto& f : fields) {
    const auto it = j.find(f.key);
    if (it == j.end()) continue;
    if (!(f.number.member || f.maybe.member || f.count.member || f.flag.member || f.text.member))
      throw std::logic_error(fmt::format("{}: /{} is read by a getter and cannot be read back", where, f.key));
    const auto wrong = [&](const char* want) {
      return std::runtime_error(fmt::format("{}: /{} is {}, expected {}", where, f.key, it->type_name(), want));
    };
    if (f.maybe) {
      if (!it->is_null() && !it->is_number()) throw wrong("a number or null");
      r.*f.maybe.member = it->is_null() ? std::nullopt : std::optional<double>(it->template get<double>());
    } else if (f.number) {
      if (!it->is_null() && !it->is_number()) throw wrong("a number or null");
      r.*f.number.member = it->is_null() ? kNotRecorded : it->template get<double>();
    } else if (f.count) {
      if (!it->is_number_integer()) throw wrong("an integer");
      r.*f.count.member = it->template get<long long>();
    } else if (f.flag) {
      if (!it->is_boolean()) throw wrong("true or false");
      r.*f.flag.member = it->template get<bool>();
    } else {
      if (!it->is_string()) throw wrong("a string");
      r.*f.text.member = it->template get<std::string>();
    }
  }
  return r;
}

}  // namespace gravsweep::results
