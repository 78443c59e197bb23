// A record's field table: one row per field (its key, unit and the member it lives in), from which
// the record's JSON is written and read. A record that a job reports (the report of a bed) is a
// struct with such a table; nothing else lists its keys. (A drop's DEM figures have a table of
// getters instead, job_reports.h: they are read from the drop's own record, not kept in a struct.)
#pragma once
#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include <limits>
#include <optional>
#include <stdexcept>
#include <string>
#include <vector>

namespace gravsweep::results {

/// A number a record did not get (a file of an older build): NaN, null in JSON.
inline constexpr double kNotRecorded = std::numeric_limits<double>::quiet_NaN();

/// One field of record R. Exactly one member pointer is set: a number, a number that may be
/// absent (JSON null), a count, a flag or a text.
template <class R>
struct RecordField {
  const char* key;   ///< JSON key and results column (units in the name)
  const char* unit;  ///< SI unit; "1" for counts and flags, "" for text
  double R::*number = nullptr;
  std::optional<double> R::*maybe = nullptr;
  long long R::*count = nullptr;
  bool R::*flag = nullptr;
  std::string R::*text = nullptr;
  /// Its column type where a job's results row holds it: REAL, INTEGER (counts, flags) or TEXT.
  [[nodiscard]] const char* sql_type() const { return number || maybe ? "REAL" : count || flag ? "INTEGER" : "TEXT"; }
};

/// Field f of r as a JSON value (an absent number as null).
template <class R>
nlohmann::json field_json(const R& r, const RecordField<R>& f) {
  if (f.number) return r.*f.number;
  if (f.maybe) return (r.*f.maybe) ? nlohmann::json(*(r.*f.maybe)) : nlohmann::json(nullptr);
  if (f.count) return r.*f.count;
  if (f.flag) return r.*f.flag;
  return r.*f.text;
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
/// key of the wrong type is an error naming `where` and the key.
template <class R>
R record_of_json(const nlohmann::json& j, const std::vector<RecordField<R>>& fields, const std::string& where) {
  if (!j.is_object())
    throw std::runtime_error(fmt::format("{}: expected a JSON object, found {}", where, j.type_name()));
  R r;
  for (const auto& f : fields) {
    const auto it = j.find(f.key);
    if (it == j.end()) continue;
    const auto wrong = [&](const char* want) {
      return std::runtime_error(fmt::format("{}: /{} is {}, expected {}", where, f.key, it->type_name(), want));
    };
    if (f.maybe) {
      if (!it->is_null() && !it->is_number()) throw wrong("a number or null");
      r.*f.maybe = it->is_null() ? std::nullopt : std::optional<double>(it->template get<double>());
    } else if (f.number) {
      if (!it->is_null() && !it->is_number()) throw wrong("a number or null");
      r.*f.number = it->is_null() ? kNotRecorded : it->template get<double>();
    } else if (f.count) {
      if (!it->is_number_integer()) throw wrong("an integer");
      r.*f.count = it->template get<long long>();
    } else if (f.flag) {
      if (!it->is_boolean()) throw wrong("true or false");
      r.*f.flag = it->template get<bool>();
    } else {
      if (!it->is_string()) throw wrong("a string");
      r.*f.text = it->template get<std::string>();
    }
  }
  return r;
}

}  // namespace gravsweep::results
