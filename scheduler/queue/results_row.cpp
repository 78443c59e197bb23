// A finished job's row of the results table: the fixed columns (fixed_result_columns), its swept
// parameters, and its metrics in the columns its kind declared at submit (results_table.cpp).
#include <fmt/format.h>

#include <set>

#include "scheduler/queue/canonical.h"
#include "scheduler/queue/queue_internal.h"

namespace gravsweep::queue::detail {

namespace {

void bind_json_value(Statement& st, int idx, const json& v) {
  if (v.is_null())
    st.bind_null(idx);
  else if (v.is_boolean())
    st.bind(idx, static_cast<std::int64_t>(v.get<bool>() ? 1 : 0));
  else if (v.is_number_integer() || v.is_number_unsigned())
    st.bind(idx, v.get<std::int64_t>());
  else if (v.is_number())
    st.bind(idx, v.get<double>());
  else if (v.is_string())
    st.bind(idx, v.get<std::string>());
  else
    st.bind(idx, queue::canonical_json(v));
}

/// The job the finished one depended on (a drop's bed); empty when none.
std::string dependency_of(Database& db, const std::string& job_id) {
  Statement st(db, "SELECT dep_id FROM job_deps WHERE job_id=?");
  st.bind(1, job_id);
  return st.step() ? st.get_text(0) : std::string();
}

}  // namespace

void insert_results_row(Database& db, const Claim& c, const Completion& done, double now,
                        const std::string& code_version) {
  check_outputs(c.kind, done);
  const auto cols = result_extra_columns(db);
  const std::string bed_id = dependency_of(db, c.job_id);
  const FinishedJob job{c, done, now, code_version, bed_id};
  std::vector<std::pair<std::string, json>> values;
  std::set<std::string> used;
  for (const auto& f : fixed_result_columns()) {
    values.emplace_back(f.name, f.value(job));
    used.insert(f.name);
  }
  for (auto it = c.params.begin(); it != c.params.end(); ++it)  // typed to fit every value at submit
    if (cols.count(it.key()) && used.insert(it.key()).second) values.emplace_back(it.key(), it.value());
  done.each_output([&](const std::string& key, const json& v) {  // each from where the runner holds it
    const std::string name = output_column(key, cols);
    if (!cols.count(name))
      throw std::runtime_error(fmt::format(
          "job {}: the results column '{}' that job kind '{}' declares is missing (the job was submitted by an "
          "older gravsweep after this worker opened the campaign): open it for writing again with this build "
          "(`gravsweep work`, `submit`), which adds the columns of its kinds",
          c.job_id, name, kind_name(c.kind)));
    // A swept parameter of the same name, in a column an earlier sweep made for the output, holds it.
    if (used.insert(name).second) values.emplace_back(name, v);
  });
  std::string names, marks;
  for (const auto& [name, v] : values) {
    names += fmt::format("{}\"{}\"", names.empty() ? "" : ", ", name);
    marks += marks.empty() ? "?" : ", ?";
  }
  Statement st(db, fmt::format("INSERT INTO results({}) VALUES({})", names, marks));
  for (std::size_t i = 0; i < values.size(); ++i) bind_json_value(st, static_cast<int>(i + 1), values[i].second);
  st.run();
}

}  // namespace gravsweep::queue::detail
