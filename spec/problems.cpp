#include "spec/problems.h"

namespace gravsweep::spec {

using nlohmann::json;

namespace {

/// True when `p` is `outer` or a field inside it ("" is the whole document).
bool inside(const std::string& outer, const std::string& p) {
  return p == outer || outer.empty() || p.rfind(outer + "/", 0) == 0;
}

}  // namespace

void Problems::add(std::string pointer, const json& found, std::string expected) {
  list_.push_back({std::move(pointer), shown_value(found), std::move(expected)});
}

void Problems::add_text(std::string pointer, std::string found, std::string expected) {
  list_.push_back({std::move(pointer), std::move(found), std::move(expected)});
}

void Problems::append(const Problems& other) { list_.insert(list_.end(), other.list_.begin(), other.list_.end()); }

bool Problems::at_or_below(const std::string& pointer) const {
  for (const auto& p : list_)
    if (inside(pointer, p.pointer)) return true;
  return false;
}

bool Problems::touches(const std::string& pointer) const {
  for (const auto& p : list_)
    if (inside(p.pointer, pointer) || inside(pointer, p.pointer)) return true;
  return false;
}

bool Checks::sound(const std::string& pointer) const {
  return doc_.contains(json::json_pointer(pointer)) && !problems_.touches(pointer);
}

const json& Checks::at(const std::string& pointer) const {
  if (!sound(pointer)) throw Unsound{};
  return doc_[json::json_pointer(pointer)];
}

double Checks::num(const std::string& pointer) const {
  const json& v = at(pointer);
  if (!v.is_number()) throw Unsound{};
  return v.get<double>();
}

void Checks::bad(const std::string& pointer, const std::string& expected) {
  const json::json_pointer jp(pointer);
  problems_.add_text(pointer, doc_.contains(jp) ? doc_[jp].dump() : "nothing (missing)", expected);
}

void Checks::bad(const std::string& pointer, const std::string& found, const std::string& expected) {
  problems_.add_text(pointer, found, expected);
}

}  // namespace gravsweep::spec
