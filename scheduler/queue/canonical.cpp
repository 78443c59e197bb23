#include "scheduler/queue/canonical.h"

#include <fmt/format.h>

#include <array>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <fstream>

#include "spec/json_pointer.h"

namespace gravsweep::queue {

namespace {

constexpr double kExactIntLimit = 9007199254740992.0;  // 2^53

void write_string(std::string& out, const std::string& s) {
  out.push_back('"');
  for (const unsigned char c : s) {
    switch (c) {
      case '"':
        out += "\\\"";
        break;
      case '\\':
        out += "\\\\";
        break;
      case '\n':
        out += "\\n";
        break;
      case '\r':
        out += "\\r";
        break;
      case '\t':
        out += "\\t";
        break;
      case '\b':
        out += "\\b";
        break;
      case '\f':
        out += "\\f";
        break;
      default:
        if (c < 0x20)
          out += fmt::format("\\u{:04x}", c);
        else
          out.push_back(static_cast<char>(c));
    }
  }
  out.push_back('"');
}

void write_double(std::string& out, double v, const std::string& where) {
  if (!std::isfinite(v))
    throw CanonicalError(fmt::format("{}: found {}, expected a finite number", where.empty() ? "/" : where, v));
  if (v == 0) {  // also -0
    out.push_back('0');
    return;
  }
  if (std::abs(v) < kExactIntLimit && std::floor(v) == v) {
    out += fmt::format("{}", static_cast<long long>(v));
    return;
  }
  out += fmt::format("{}", v);  // shortest round-trip representation
}

void write(std::string& out, const nlohmann::json& j, const std::string& where) {
  using T = nlohmann::json::value_t;
  switch (j.type()) {
    case T::null:
      out += "null";
      break;
    case T::boolean:
      out += j.get<bool>() ? "true" : "false";
      break;
    case T::number_integer:
      out += fmt::format("{}", j.get<std::int64_t>());
      break;
    case T::number_unsigned:
      out += fmt::format("{}", j.get<std::uint64_t>());
      break;
    case T::number_float:
      write_double(out, j.get<double>(), where);
      break;
    case T::string:
      write_string(out, j.get_ref<const std::string&>());
      break;
    case T::array: {
      out.push_back('[');
      for (std::size_t i = 0; i < j.size(); ++i) {
        if (i) out.push_back(',');
        write(out, j[i], where + "/" + std::to_string(i));
      }
      out.push_back(']');
      break;
    }
    case T::object: {  // nlohmann::json objects are std::map: keys iterate in byte order
      out.push_back('{');
      bool first = true;
      for (auto it = j.begin(); it != j.end(); ++it) {
        if (!first) out.push_back(',');
        first = false;
        write_string(out, it.key());
        out.push_back(':');
        write(out, it.value(), spec::pointer_child(where, it.key()));
      }
      out.push_back('}');
      break;
    }
    default:
      throw CanonicalError(fmt::format("{}: unsupported JSON value (binary/discarded)", where));
  }
}

nlohmann::json normalise(const nlohmann::json& j, const std::string& where) {
  using T = nlohmann::json::value_t;
  switch (j.type()) {
    case T::number_float: {
      const double v = j.get<double>();
      if (!std::isfinite(v))
        throw CanonicalError(fmt::format("{}: found {}, expected a finite number", where.empty() ? "/" : where, v));
      if (v == 0) return 0;
      if (std::abs(v) < kExactIntLimit && std::floor(v) == v) return static_cast<std::int64_t>(v);
      return v;
    }
    case T::array: {
      nlohmann::json out = nlohmann::json::array();
      for (std::size_t i = 0; i < j.size(); ++i) out.push_back(normalise(j[i], where + "/" + std::to_string(i)));
      return out;
    }
    case T::object: {
      nlohmann::json out = nlohmann::json::object();
      for (auto it = j.begin(); it != j.end(); ++it)
        out[it.key()] = normalise(it.value(), spec::pointer_child(where, it.key()));
      return out;
    }
    default:
      return j;
  }
}

}  // namespace

std::string canonical_json(const nlohmann::json& j) {
  std::string out;
  write(out, j, "");
  return out;
}

nlohmann::json canonicalize(const nlohmann::json& j) { return normalise(j, ""); }

double round_decimal(double v, int digits) {
  if (!std::isfinite(v) || v == 0) return v == 0 ? 0.0 : v;
  const std::string s = fmt::format("{:.{}g}", v, digits);
  return std::strtod(s.c_str(), nullptr);
}

std::string sha256_file(const std::filesystem::path& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw std::runtime_error(fmt::format("cannot read '{}' to checksum it", path.string()));
  Sha256 h;
  std::array<char, 1 << 16> buf{};
  while (in) {
    in.read(buf.data(), buf.size());
    h.update(buf.data(), static_cast<std::size_t>(in.gcount()));
  }
  if (in.bad()) throw std::runtime_error(fmt::format("read error on '{}' while checksumming", path.string()));
  return h.hex_digest();
}

std::string job_id(std::string_view kind, const nlohmann::json& params) {
  std::string text = "gravsweep-job/1\n";
  text += kind;
  text += '\n';
  text += canonical_json(params);
  return sha256_hex(text).substr(0, 20);
}

}  // namespace gravsweep::queue
