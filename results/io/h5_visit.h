// One visit function per file layout, run by a Writer to write a record and by a Reader to read
// it back: the layout is written once, so the two directions cannot drift apart (the checkpoint
// and the bed file are laid out this way). Both hash every value they pass (ContentHash), in
// the visit's order: a file that stores the writer's hash is checked by the reader's.
#pragma once
#include <fmt/format.h>

#include <cmath>
#include <cstdint>
#include <cstring>
#include <limits>
#include <optional>
#include <string>
#include <type_traits>
#include <vector>

#include "engine/core/particles.h"
#include "engine/core/types.h"
#include "results/io/hdf5.h"

namespace gravsweep::results::h5visit {

/// FNV-1a over 64-bit words (the last word zero-padded), with the byte count folded in: each
/// step (xor, multiply by an odd prime) is a bijection of the state, so any one changed word
/// changes the result.
class ContentHash {
 public:
  void bytes(const void* data, std::size_t n) {
    const auto* p = static_cast<const unsigned char*>(data);
    std::size_t k = 0;
    for (; k + 8 <= n; k += 8) {
      std::uint64_t w = 0;
      std::memcpy(&w, p + k, 8);
      word(w);
    }
    if (k < n) {
      std::uint64_t w = 0;
      std::memcpy(&w, p + k, n - k);
      word(w);
    }
    word(n);
  }
  template <class T>
  void value(const T& v) {
    static_assert(std::is_arithmetic_v<T>);
    bytes(&v, sizeof v);
  }
  void value(const Vec3& v) { bytes(v.data(), 3 * sizeof(double)); }
  [[nodiscard]] std::string hex() const { return fmt::format("fnv1a64:{:016x}", h_); }

 private:
  static constexpr std::uint64_t kOffset = 14695981039346656037ULL, kPrime = 1099511628211ULL;
  std::uint64_t h_ = kOffset;
  void word(std::uint64_t w) { h_ = (h_ ^ w) * kPrime; }
};

// Records as they are in memory and in the file: the type, the columns of a (N, width) dataset
// and how the hash reads them (field by field where the struct has padding).
template <class M, class T>
std::size_t offset_in(const T& obj, const M& member) {
  return static_cast<std::size_t>(reinterpret_cast<const char*>(&member) - reinterpret_cast<const char*>(&obj));
}

inline h5::Handle copy_type(hid_t t) { return h5::Handle(H5Tcopy(t), &H5Tclose); }

inline h5::Handle vec3_type() {
  const hsize_t three = 3;
  return h5::Handle(H5Tarray_create2(H5T_NATIVE_DOUBLE, 1, &three), &H5Tclose);
}

template <class T>
struct Rec {
  static_assert(std::is_same_v<T, double> || std::is_same_v<T, Vec3> || std::is_same_v<T, std::uint32_t> ||
                std::is_same_v<T, std::int32_t> || std::is_same_v<T, std::uint8_t> || std::is_same_v<T, SizeClass>);
  static h5::Handle type() {
    if constexpr (std::is_same_v<T, std::uint32_t>)
      return copy_type(H5T_NATIVE_UINT32);
    else if constexpr (std::is_same_v<T, std::int32_t>)
      return copy_type(H5T_NATIVE_INT32);
    else if constexpr (std::is_same_v<T, std::uint8_t> || std::is_same_v<T, SizeClass>)
      return copy_type(H5T_NATIVE_UINT8);
    else
      return copy_type(H5T_NATIVE_DOUBLE);  // double, and Vec3 as three columns
  }
  static constexpr hsize_t width = std::is_same_v<T, Vec3> ? 3 : 1;
  static void hash(ContentHash& h, const std::vector<T>& v) { h.bytes(v.data(), v.size() * sizeof(T)); }
};

/// Writes what a visit function shows it, hashing every value.
struct Writer {
  static constexpr bool kReading = false;
  ContentHash hash;
  h5::Storage storage = h5::Storage::contiguous;  ///< of the arrays (a checkpoint: contiguous)
  h5::Handle group(hid_t parent, const char* name) { return h5::create_group(parent, name); }
  void attr(hid_t obj, const char* name, double& v) {
    h5::set_attr(obj, name, v);
    hash.value(v);
  }
  void attr(hid_t obj, const char* name, long long& v) {
    h5::set_attr(obj, name, v);
    hash.value(v);
  }
  void attr(hid_t obj, const char* name, std::string& v) {
    h5::set_attr(obj, name, v);
    hash.bytes(v.data(), v.size());
  }
  template <class T>
  void array(hid_t g, const char* name, std::vector<T>& v, const char* units, const char* description) {
    std::vector<hsize_t> dims{v.size()};
    if (Rec<T>::width > 1) dims.push_back(Rec<T>::width);
    h5::write_raw(g, name, Rec<T>::type(), v.data(), dims, units, description, storage);
    Rec<T>::hash(hash, v);
  }
  /// Doubles kept flat in memory, `width` a row, as an (N, width) dataset.
  void rows(hid_t g, const char* name, std::vector<double>& v, hsize_t width, const char* units,
            const char* description) {
    if (v.size() % width != 0)
      throw h5::H5Error(fmt::format("{}/{}: {} values are not rows of {}", h5::where(g), name, v.size(), width));
    h5::write_raw(g, name, Rec<double>::type(), v.data(), {v.size() / width, width}, units, description, storage);
    Rec<double>::hash(hash, v);
  }
};

/// Reads what a visit function asks for, hashing every value as the writer did.
struct Reader {
  static constexpr bool kReading = true;
  ContentHash hash;
  h5::Handle group(hid_t parent, const char* name) { return h5::open_group(parent, name); }
  void attr(hid_t obj, const char* name, double& v) {
    v = h5::get_attr_double(obj, name);
    hash.value(v);
  }
  void attr(hid_t obj, const char* name, long long& v) {
    v = h5::get_attr_int(obj, name);
    hash.value(v);
  }
  void attr(hid_t obj, const char* name, std::string& v) {
    v = h5::get_attr_string(obj, name);
    hash.bytes(v.data(), v.size());
  }
  template <class T>
  void array(hid_t g, const char* name, std::vector<T>& v, const char*, const char*) {
    const std::vector<hsize_t> dims = h5::dataset_dims(g, name);
    if (dims.size() != (Rec<T>::width > 1 ? 2u : 1u) || (Rec<T>::width > 1 && dims[1] != Rec<T>::width))
      throw h5::H5Error(fmt::format("{}/{}: shape of rank {}, expected (N{})", h5::where(g), name, dims.size(),
                                    Rec<T>::width > 1 ? ", 3" : ""));
    v.resize(static_cast<std::size_t>(dims[0]));
    h5::read_raw(g, name, Rec<T>::type(), v.data());
    Rec<T>::hash(hash, v);
  }
  void rows(hid_t g, const char* name, std::vector<double>& v, hsize_t width, const char*, const char*) {
    const std::vector<hsize_t> dims = h5::dataset_dims(g, name);
    if (dims.size() != 2 || dims[1] != width)
      throw h5::H5Error(fmt::format("{}/{}: must have shape (N, {})", h5::where(g), name, width));
    v.resize(static_cast<std::size_t>(dims[0] * width));
    h5::read_raw(g, name, Rec<double>::type(), v.data());
    Rec<double>::hash(hash, v);
  }
};

/// Integers and flags of other types go through a long long.
template <class Io, class T>
void number(Io& io, hid_t obj, const char* name, T& v) {
  auto x = static_cast<long long>(v);
  io.attr(obj, name, x);
  if constexpr (Io::kReading) v = static_cast<T>(x);
}

/// An optional time: NaN when empty.
template <class Io>
void optional_time(Io& io, hid_t obj, const char* name, std::optional<double>& v) {
  double x = v.value_or(std::numeric_limits<double>::quiet_NaN());
  io.attr(obj, name, x);
  if constexpr (Io::kReading) v = std::isnan(x) ? std::nullopt : std::optional<double>(x);
}

}  // namespace gravsweep::results::h5visit
