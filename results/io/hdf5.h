// A small RAII layer on the HDF5 C API: every hid_t lives in an owning Handle that closes it with
// the right H5*close function. Errors throw H5Error naming the file, the object and what failed.
// Conventions of gravsweep's files: every numeric dataset carries a "units" attribute (SI, e.g.
// "m", "m/s", "m/s2", "1" for counts) and a "description"; strings are variable-length UTF-8 so
// that h5py returns them as str.
#pragma once
#include <hdf5.h>

#include <cstdint>
#include <filesystem>
#include <stdexcept>
#include <string>
#include <vector>

namespace gravsweep::results::h5 {

/// An HDF5 call failed, or a file does not have the expected layout.
class H5Error : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

/// Owns one HDF5 identifier.
class Handle {
 public:
  using Closer = herr_t (*)(hid_t);
  Handle() = default;
  Handle(hid_t id, Closer closer) : id_(id), closer_(closer) {}
  ~Handle() { reset(); }
  Handle(const Handle&) = delete;
  Handle& operator=(const Handle&) = delete;
  Handle(Handle&& o) noexcept : id_(o.id_), closer_(o.closer_) { o.id_ = H5I_INVALID_HID; }
  Handle& operator=(Handle&& o) noexcept {
    if (this != &o) {
      reset();
      id_ = o.id_;
      closer_ = o.closer_;
      o.id_ = H5I_INVALID_HID;
    }
    return *this;
  }
  /// Gives up ownership without closing.
  hid_t release() {
    const hid_t id = id_;
    id_ = H5I_INVALID_HID;
    return id;
  }
  void reset() {
    if (id_ >= 0 && closer_) closer_(id_);
    id_ = H5I_INVALID_HID;
  }
  [[nodiscard]] hid_t get() const { return id_; }
  operator hid_t() const { return id_; }  // NOLINT: handles are passed straight to the C API

 private:
  hid_t id_ = H5I_INVALID_HID;
  Closer closer_ = nullptr;
};

/// Where a file being written lives until close().
///  - memory: HDF5 builds the whole file in memory (its core driver, no backing store) and close()
///    writes the image to disk with plain POSIX calls. A full or failing disk is then an error of
///    ours, thrown with the errno's text, and never an error inside HDF5 (whose library keeps a
///    file whose close failed and crashes on it in its exit handler, HDF5 1.10).
///  - streaming: written through to disk as it grows (snapshot series, which may be larger than
///    memory); a disk that fills under it can still fail inside HDF5.
enum class Backing { memory, streaming };

/// An open HDF5 file; remembers its path for error messages.
class File {
 public:
  /// Creates (truncates) a file for writing.
  static File create(const std::filesystem::path& path, Backing backing = Backing::memory);
  /// Opens an existing file read-only.
  static File open_read(const std::filesystem::path& path);
  [[nodiscard]] hid_t id() const { return handle_.get(); }
  [[nodiscard]] const std::filesystem::path& path() const { return path_; }
  /// Flushes and closes now (errors surface here rather than in a destructor). A memory-backed
  /// file is written to its path here; a file destroyed without close() leaves nothing on disk.
  void close();

 private:
  Handle handle_;
  std::filesystem::path path_;
  Backing backing_ = Backing::streaming;
};

/// Creates a group `name` under `parent`.
Handle create_group(hid_t parent, const std::string& name);
/// Opens group `name` under `parent`; throws naming the file when it is missing.
Handle open_group(hid_t parent, const std::string& name);
/// True when a link `name` exists under `parent`.
bool exists(hid_t parent, const std::string& name);

/// compressed: datasets of 4096 values or more are chunked, shuffled and deflated (level 4);
/// contiguous: stored as they are (grain snapshots: state doubles hardly compress, BENCHMARKS.md).
enum class Storage { compressed, contiguous };

/// Writes a dataset of doubles with shape `dims` (row-major), plus "units" and "description".
void write_doubles(hid_t parent, const std::string& name, const std::vector<double>& data,
                   const std::vector<hsize_t>& dims, const std::string& units, const std::string& description,
                   Storage storage = Storage::compressed);
void write_int32(hid_t parent, const std::string& name, const std::vector<std::int32_t>& data, const std::string& units,
                 const std::string& description, Storage storage = Storage::compressed);
void write_uint8(hid_t parent, const std::string& name, const std::vector<std::uint8_t>& data, const std::string& units,
                 const std::string& description);

/// Writes records of `type` (a native type or a compound type) straight from memory as a dataset
/// of shape `dims`, in the file with the same type (no copy, no conversion: the visit functions of
/// h5_visit.h, for checkpoints contiguous, for beds compressed). Plus "units" and "description".
void write_raw(hid_t parent, const std::string& name, hid_t type, const void* data, const std::vector<hsize_t>& dims,
               const std::string& units, const std::string& description, Storage storage = Storage::contiguous);
/// The shape of dataset `name` under `parent` (throws naming the file when it is missing).
std::vector<hsize_t> dataset_dims(hid_t parent, const std::string& name);
/// Reads dataset `name` as records of `mem_type` into `data`, which has room for the whole
/// dataset (its dataset_dims); throws naming the file and the dataset when it cannot.
void read_raw(hid_t parent, const std::string& name, hid_t mem_type, void* data);

/// Reads a dataset of any numeric type as doubles; `dims_out` receives its shape.
std::vector<double> read_doubles(hid_t parent, const std::string& name, std::vector<hsize_t>* dims_out = nullptr);
std::vector<std::int32_t> read_int32(hid_t parent, const std::string& name);
std::vector<std::uint8_t> read_uint8(hid_t parent, const std::string& name);

/// Attributes on a file, group or dataset.
void set_attr(hid_t obj, const std::string& name, const std::string& value);
void set_attr(hid_t obj, const std::string& name, const char* value);
void set_attr(hid_t obj, const std::string& name, double value);
void set_attr(hid_t obj, const std::string& name, long long value);
bool has_attr(hid_t obj, const std::string& name);
std::string get_attr_string(hid_t obj, const std::string& name);
double get_attr_double(hid_t obj, const std::string& name);
long long get_attr_int(hid_t obj, const std::string& name);
/// "units" attribute of dataset `name` under `parent` (empty if missing).
std::string dataset_units(hid_t parent, const std::string& name);

/// Name of the file an object belongs to and the object's path, for messages: "f.h5:/grains".
std::string where(hid_t obj);

/// Writes through `write(tmp_path)` to a temporary file next to `final_path`, then renames it into
/// place, so a reader never sees a half-written file; the temporary is removed on failure.
template <class Fn>
void write_atomically(const std::filesystem::path& final_path, Fn&& write);

std::filesystem::path temporary_sibling(const std::filesystem::path& final_path);

template <class Fn>
void write_atomically(const std::filesystem::path& final_path, Fn&& write) {
  const auto tmp = temporary_sibling(final_path);
  try {
    write(tmp);
    std::filesystem::rename(tmp, final_path);
  } catch (...) {
    std::error_code ec;
    std::filesystem::remove(tmp, ec);
    throw;
  }
}

}  // namespace gravsweep::results::h5
