#include "scheduler/sweep/canonical.h"

#include <fmt/format.h>

#include <array>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <fstream>

#include "spec/json_pointer.h"

namespace gravsweep::sweep {

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

constexpr std::array<std::uint32_t, 64> kK = {
    0x428a2f98, 0x71374491, 0xb5c0fbcf, 0xe9b5dba5, 0x3956c25b, 0x59f111f1, 0x923f82a4, 0xab1c5ed5,
    0xd807aa98, 0x12835b01, 0x243185be, 0x550c7dc3, 0x72be5d74, 0x80deb1fe, 0x9bdc06a7, 0xc19bf174,
    0xe49b69c1, 0xefbe4786, 0x0fc19dc6, 0x240ca1cc, 0x2de92c6f, 0x4a7484aa, 0x5cb0a9dc, 0x76f988da,
    0x983e5152, 0xa831c66d, 0xb00327c8, 0xbf597fc7, 0xc6e00bf3, 0xd5a79147, 0x06ca6351, 0x14292967,
    0x27b70a85, 0x2e1b2138, 0x4d2c6dfc, 0x53380d13, 0x650a7354, 0x766a0abb, 0x81c2c92e, 0x92722c85,
    0xa2bfe8a1, 0xa81a664b, 0xc24b8b70, 0xc76c51a3, 0xd192e819, 0xd6990624, 0xf40e3585, 0x106aa070,
    0x19a4c116, 0x1e376c08, 0x2748774c, 0x34b0bcb5, 0x391c0cb3, 0x4ed8aa4a, 0x5b9cca4f, 0x682e6ff3,
    0x748f82ee, 0x78a5636f, 0x84c87814, 0x8cc70208, 0x90befffa, 0xa4506ceb, 0xbef9a3f7, 0xc67178f2};

inline std::uint32_t rotr(std::uint32_t x, int n) { return (x >> n) | (x << (32 - n)); }

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

Sha256::Sha256() : h_{0x6a09e667, 0xbb67ae85, 0x3c6ef372, 0xa54ff53a, 0x510e527f, 0x9b05688c, 0x1f83d9ab, 0x5be0cd19} {}

void Sha256::block(const unsigned char* p) {
  std::uint32_t w[64];
  for (int i = 0; i < 16; ++i)
    w[i] = (std::uint32_t(p[4 * i]) << 24) | (std::uint32_t(p[4 * i + 1]) << 16) | (std::uint32_t(p[4 * i + 2]) << 8) |
           std::uint32_t(p[4 * i + 3]);
  for (int i = 16; i < 64; ++i) {
    const std::uint32_t s0 = rotr(w[i - 15], 7) ^ rotr(w[i - 15], 18) ^ (w[i - 15] >> 3);
    const std::uint32_t s1 = rotr(w[i - 2], 17) ^ rotr(w[i - 2], 19) ^ (w[i - 2] >> 10);
    w[i] = w[i - 16] + s0 + w[i - 7] + s1;
  }
  std::uint32_t a = h_[0], b = h_[1], c = h_[2], d = h_[3], e = h_[4], f = h_[5], g = h_[6], h = h_[7];
  for (int i = 0; i < 64; ++i) {
    const std::uint32_t S1 = rotr(e, 6) ^ rotr(e, 11) ^ rotr(e, 25);
    const std::uint32_t ch = (e & f) ^ (~e & g);
    const std::uint32_t t1 = h + S1 + ch + kK[static_cast<std::size_t>(i)] + w[i];
    const std::uint32_t S0 = rotr(a, 2) ^ rotr(a, 13) ^ rotr(a, 22);
    const std::uint32_t maj = (a & b) ^ (a & c) ^ (b & c);
    const std::uint32_t t2 = S0 + maj;
    h = g;
    g = f;
    f = e;
    e = d + t1;
    d = c;
    c = b;
    b = a;
    a = t1 + t2;
  }
  h_[0] += a;
  h_[1] += b;
  h_[2] += c;
  h_[3] += d;
  h_[4] += e;
  h_[5] += f;
  h_[6] += g;
  h_[7] += h;
}

void Sha256::update(const void* data, std::size_t n) {
  const auto* p = static_cast<const unsigned char*>(data);
  total_ += n;
  while (n > 0) {
    if (buf_len_ == 0 && n >= 64) {
      block(p);
      p += 64;
      n -= 64;
      continue;
    }
    const std::size_t take = std::min<std::size_t>(64 - buf_len_, n);
    std::copy(p, p + take, buf_ + buf_len_);
    buf_len_ += take;
    p += take;
    n -= take;
    if (buf_len_ == 64) {
      block(buf_);
      buf_len_ = 0;
    }
  }
}

std::string Sha256::hex_digest() {
  const std::uint64_t bits = total_ * 8;
  const unsigned char one = 0x80, zero = 0;
  update(&one, 1);
  while (buf_len_ != 56) update(&zero, 1);
  unsigned char len[8];
  for (int i = 0; i < 8; ++i) len[i] = static_cast<unsigned char>(bits >> (56 - 8 * i));
  update(len, 8);
  std::string out;
  out.reserve(64);
  for (std::uint32_t v : h_) out += fmt::format("{:08x}", v);
  return out;
}

std::string sha256_hex(std::string_view bytes) {
  Sha256 h;
  h.update(bytes.data(), bytes.size());
  return h.hex_digest();
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

}  // namespace gravsweep::sweep
