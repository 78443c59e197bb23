// The one way a spec's problems are collected (scenario, sweep and model specs alike): the schema's
// validator appends to a Problems list, then the rules across fields run on the fields it left
// sound (Checks), each rule recording its problems and going on, so that a user sees every
// problem of a file at once, each with its JSON pointer, the value found and what was expected.
#pragma once
#include <nlohmann/json.hpp>

#include <string>
#include <vector>

#include "spec/json_schema.h"

namespace gravsweep::spec {

class Problems {
 public:
  /// The problems so far, in the order found (the schema validator appends here).
  [[nodiscard]] std::vector<SpecProblem>& list() { return list_; }
  [[nodiscard]] const std::vector<SpecProblem>& list() const { return list_; }
  [[nodiscard]] bool empty() const { return list_.empty(); }
  [[nodiscard]] std::size_t size() const { return list_.size(); }

  /// A problem at `pointer`: `found` shown as shown_value() does (compact JSON and its type).
  void add(std::string pointer, const nlohmann::json& found, std::string expected);
  /// A problem at `pointer` with the found part as given (an error's text, "nothing (missing)").
  void add_text(std::string pointer, std::string found, std::string expected);
  /// Appends `other`'s problems after these, in their order.
  void append(const Problems& other);
  /// True when a problem lies at `pointer` or below it.
  [[nodiscard]] bool at_or_below(const std::string& pointer) const;
  /// True when a problem lies at `pointer`, below it or at a field around it.
  [[nodiscard]] bool touches(const std::string& pointer) const;

 private:
  std::vector<SpecProblem> list_;
};

/// The fields of a document whose problems are being collected, as the rules across fields read
/// them: a rule reads only sound fields (present, and no problem at, around or inside them), so
/// that a field already found bad is reported once.
class Checks {
 public:
  Checks(const nlohmann::json& doc, Problems& problems) : doc_(doc), problems_(problems) {}

  /// Runs one rule; the rule stops quietly at the first field it reads that is not sound.
  template <class F>
  void run(F&& rule) {
    try {
      rule();
    } catch (const Unsound&) {
    }
  }
  /// True when `pointer` exists and no problem touches it.
  [[nodiscard]] bool sound(const std::string& pointer) const;
  /// The field at `pointer`; stops the running rule when it is not sound.
  [[nodiscard]] const nlohmann::json& at(const std::string& pointer) const;
  /// The number at `pointer`; stops the running rule when it is not a sound number.
  [[nodiscard]] double num(const std::string& pointer) const;
  /// The field at `pointer` is bad: its value is shown as found (or "nothing (missing)").
  void bad(const std::string& pointer, const std::string& expected);
  void bad(const std::string& pointer, const std::string& found, const std::string& expected);
  [[nodiscard]] Problems& problems() { return problems_; }

 private:
  struct Unsound {};
  const nlohmann::json& doc_;
  Problems& problems_;
};

}  // namespace gravsweep::spec
