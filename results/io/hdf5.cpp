#include "results/io/hdf5.h"

#include <fmt/format.h>
#include <fcntl.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>

#include <atomic>

namespace gravsweep::results::h5 {

namespace {

/// HDF5 prints its own error stack by default; we report errors ourselves.
void silence_hdf5() {
  static std::atomic<bool> done{false};
  if (!done.exchange(true)) H5Eset_auto2(H5E_DEFAULT, nullptr, nullptr);
}

std::string name_of(hid_t id, ssize_t (*get)(hid_t, char*, size_t)) {
  const ssize_t n = get(id, nullptr, 0);
  if (n <= 0) return "?";
  std::string s(static_cast<std::size_t>(n) + 1, '\0');
  get(id, s.data(), s.size());
  s.resize(static_cast<std::size_t>(n));
  return s;
}

ssize_t iget_name(hid_t id, char* buf, size_t size) { return H5Iget_name(id, buf, size); }
ssize_t fget_name(hid_t id, char* buf, size_t size) { return H5Fget_name(id, buf, size); }

[[noreturn]] void fail(hid_t obj, const std::string& what) {
  throw H5Error(fmt::format("HDF5 {}: {}", where(obj), what));
}

Handle string_type() {
  Handle t(H5Tcopy(H5T_C_S1), &H5Tclose);
  H5Tset_size(t, H5T_VARIABLE);
  H5Tset_cset(t, H5T_CSET_UTF8);
  return t;
}

/// Opens the link `name` of `parent` with `open` (H5Dopen2, H5Gopen2), closed by `close`: a
/// missing link and one that does not open are two messages, each naming the `kind` of object.
Handle open_link(hid_t parent, const std::string& name, const char* kind, hid_t (*open)(hid_t, const char*, hid_t),
                 Handle::Closer close) {
  if (!exists(parent, name)) fail(parent, fmt::format("{} '{}' is missing", kind, name));
  Handle h(open(parent, name.c_str(), H5P_DEFAULT), close);
  if (h.get() < 0) fail(parent, fmt::format("cannot open {} '{}'", kind, name));
  return h;
}

Handle open_dataset(hid_t parent, const std::string& name) {
  return open_link(parent, name, "dataset", &H5Dopen2, &H5Dclose);
}

/// The number of values of an array of shape `dims` (1 for a scalar's empty shape).
hsize_t element_count(const std::vector<hsize_t>& dims) {
  hsize_t total = 1;
  for (hsize_t d : dims) total *= d;
  return total;
}

/// The shape of the dataspace `space` of dataset `name` of `parent` (named in the error).
std::vector<hsize_t> shape_of(hid_t parent, const std::string& name, hid_t space) {
  const int rank = H5Sget_simple_extent_ndims(space);
  if (rank < 0) fail(parent, fmt::format("cannot read the shape of '{}'", name));
  std::vector<hsize_t> dims(static_cast<std::size_t>(rank));
  H5Sget_simple_extent_dims(space, dims.data(), nullptr);
  return dims;
}

void write_dataset(hid_t parent, const std::string& name, hid_t file_type, hid_t mem_type, const void* data,
                   const std::vector<hsize_t>& dims, const std::string& units, const std::string& description,
                   Storage storage = Storage::compressed) {
  Handle space(H5Screate_simple(static_cast<int>(dims.size()), dims.data(), nullptr), &H5Sclose);
  if (space.get() < 0) fail(parent, fmt::format("cannot create dataspace for '{}'", name));
  Handle plist(H5Pcreate(H5P_DATASET_CREATE), &H5Pclose);
  const hsize_t total = element_count(dims);
  // Compress larger datasets (chunked along the first axis); small ones stay contiguous.
  if (storage == Storage::compressed && total >= 4096 && !dims.empty()) {
    std::vector<hsize_t> chunk = dims;
    chunk[0] = std::min<hsize_t>(dims[0], 16384);
    H5Pset_chunk(plist, static_cast<int>(chunk.size()), chunk.data());
    H5Pset_shuffle(plist);
    H5Pset_deflate(plist, 4);
  }
  Handle ds(H5Dcreate2(parent, name.c_str(), file_type, space, H5P_DEFAULT, plist, H5P_DEFAULT), &H5Dclose);
  if (ds.get() < 0) fail(parent, fmt::format("cannot create dataset '{}'", name));
  if (total > 0 && H5Dwrite(ds, mem_type, H5S_ALL, H5S_ALL, H5P_DEFAULT, data) < 0)
    fail(parent, fmt::format("cannot write dataset '{}'", name));
  set_attr(ds, "units", units);
  set_attr(ds, "description", description);
}

template <class T>
std::vector<T> read_dataset(hid_t parent, const std::string& name, hid_t mem_type, std::vector<hsize_t>* dims_out) {
  Handle ds = open_dataset(parent, name);
  Handle space(H5Dget_space(ds), &H5Sclose);
  const std::vector<hsize_t> dims = shape_of(parent, name, space);
  const hsize_t total = element_count(dims);
  std::vector<T> out(static_cast<std::size_t>(total));
  if (total > 0 && H5Dread(ds, mem_type, H5S_ALL, H5S_ALL, H5P_DEFAULT, out.data()) < 0)
    fail(parent, fmt::format("cannot read dataset '{}' as {}", name, sizeof(T) == 8 ? "double" : "integer"));
  if (dims_out) *dims_out = dims;
  return out;
}

Handle open_attr(hid_t obj, const std::string& name) {
  if (H5Aexists(obj, name.c_str()) <= 0) fail(obj, fmt::format("attribute '{}' is missing", name));
  Handle a(H5Aopen(obj, name.c_str(), H5P_DEFAULT), &H5Aclose);
  if (a.get() < 0) fail(obj, fmt::format("cannot open attribute '{}'", name));
  return a;
}

void replace_attr(hid_t obj, const std::string& name) {
  if (H5Aexists(obj, name.c_str()) > 0) H5Adelete(obj, name.c_str());
}

template <class T>
void set_scalar_attr(hid_t obj, const std::string& name, hid_t file_type, hid_t mem_type, T value) {
  replace_attr(obj, name);
  Handle space(H5Screate(H5S_SCALAR), &H5Sclose);
  Handle a(H5Acreate2(obj, name.c_str(), file_type, space, H5P_DEFAULT, H5P_DEFAULT), &H5Aclose);
  if (a.get() < 0 || H5Awrite(a, mem_type, &value) < 0) fail(obj, fmt::format("cannot write attribute '{}'", name));
}

/// The in-memory file grows by this much at a time.
constexpr std::size_t kMemoryFileIncrementBytes = 4u << 20;

/// Writes a memory-backed file's image to `path` (created by File::create), naming the errno.
void write_image(const std::filesystem::path& path, const std::vector<char>& image) {
  const int fd = ::open(path.c_str(), O_WRONLY | O_TRUNC | O_CLOEXEC);
  if (fd < 0) throw H5Error(fmt::format("HDF5 {}: cannot open to write: {}", path.string(), std::strerror(errno)));
  std::size_t done = 0;
  while (done < image.size()) {
    const ssize_t w = ::write(fd, image.data() + done, image.size() - done);
    if (w < 0 && errno == EINTR) continue;
    if (w <= 0) {
      const int err = errno;
      ::close(fd);
      throw H5Error(fmt::format("HDF5 {}: cannot write ({} of {} bytes written): {}", path.string(), done, image.size(),
                                std::strerror(err)));
    }
    done += static_cast<std::size_t>(w);
  }
  if (::close(fd) != 0) throw H5Error(fmt::format("HDF5 {}: cannot write: {}", path.string(), std::strerror(errno)));
}

}  // namespace

std::string where(hid_t obj) { return fmt::format("{}:{}", name_of(obj, &fget_name), name_of(obj, &iget_name)); }

std::filesystem::path temporary_sibling(const std::filesystem::path& final_path) {
  auto tmp = final_path;
  tmp += fmt::format(".tmp{}", static_cast<long>(::getpid()));
  return tmp;
}

File File::create(const std::filesystem::path& path, Backing backing) {
  silence_hdf5();
  File f;
  f.path_ = path;
  f.backing_ = backing;
  Handle fapl(H5Pcreate(H5P_FILE_ACCESS), &H5Pclose);
  if (backing == Backing::memory) {
    // Fail now, as the streaming file would, when the folder cannot take the file.
    const int fd = ::open(path.c_str(), O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC, 0644);
    if (fd < 0)
      throw H5Error(fmt::format("HDF5 {}: cannot create the file ({}; does the folder exist and is it writable?)",
                                path.string(), std::strerror(errno)));
    ::close(fd);
    if (H5Pset_fapl_core(fapl, kMemoryFileIncrementBytes, 0) < 0)
      throw H5Error(fmt::format("HDF5 {}: cannot set up an in-memory file", path.string()));
  }
  f.handle_ = Handle(H5Fcreate(path.c_str(), H5F_ACC_TRUNC, H5P_DEFAULT, fapl), &H5Fclose);
  if (f.handle_.get() < 0)
    throw H5Error(
        fmt::format("HDF5 {}: cannot create the file (does the folder exist and is it "
                    "writable?)",
                    path.string()));
  return f;
}

File File::open_read(const std::filesystem::path& path) {
  silence_hdf5();
  if (!std::filesystem::exists(path)) throw H5Error(fmt::format("HDF5 {}: no such file", path.string()));
  if (H5Fis_hdf5(path.c_str()) <= 0) throw H5Error(fmt::format("HDF5 {}: not an HDF5 file", path.string()));
  File f;
  f.path_ = path;
  f.handle_ = Handle(H5Fopen(path.c_str(), H5F_ACC_RDONLY, H5P_DEFAULT), &H5Fclose);
  if (f.handle_.get() < 0) throw H5Error(fmt::format("HDF5 {}: cannot open the file", path.string()));
  return f;
}

void File::close() {
  if (handle_.get() < 0) return;
  if (H5Fflush(handle_, H5F_SCOPE_LOCAL) < 0) throw H5Error(fmt::format("HDF5 {}: flush failed", path_.string()));
  std::vector<char> image;
  if (backing_ == Backing::memory) {
    const ssize_t n = H5Fget_file_image(handle_, nullptr, 0);
    if (n < 0) throw H5Error(fmt::format("HDF5 {}: cannot take the file's image", path_.string()));
    image.resize(static_cast<std::size_t>(n));
    if (H5Fget_file_image(handle_, image.data(), image.size()) != n)
      throw H5Error(fmt::format("HDF5 {}: cannot take the file's image", path_.string()));
  }
  const hid_t id = handle_.release();
  if (H5Fclose(id) < 0) throw H5Error(fmt::format("HDF5 {}: close failed", path_.string()));
  if (backing_ == Backing::memory) write_image(path_, image);
}

Handle create_group(hid_t parent, const std::string& name) {
  Handle g(H5Gcreate2(parent, name.c_str(), H5P_DEFAULT, H5P_DEFAULT, H5P_DEFAULT), &H5Gclose);
  if (g.get() < 0) fail(parent, fmt::format("cannot create group '{}'", name));
  return g;
}

Handle open_group(hid_t parent, const std::string& name) {
  return open_link(parent, name, "group", &H5Gopen2, &H5Gclose);
}

bool exists(hid_t parent, const std::string& name) { return H5Lexists(parent, name.c_str(), H5P_DEFAULT) > 0; }

void write_doubles(hid_t parent, const std::string& name, const std::vector<double>& data,
                   const std::vector<hsize_t>& dims, const std::string& units, const std::string& description,
                   Storage storage) {
  if (element_count(dims) != data.size())
    fail(parent, fmt::format("dataset '{}': {} values do not fill the shape", name, data.size()));
  write_dataset(parent, name, H5T_IEEE_F64LE, H5T_NATIVE_DOUBLE, data.data(), dims, units, description, storage);
}

void write_int32(hid_t parent, const std::string& name, const std::vector<std::int32_t>& data, const std::string& units,
                 const std::string& description, Storage storage) {
  write_dataset(parent, name, H5T_STD_I32LE, H5T_NATIVE_INT32, data.data(), {data.size()}, units, description, storage);
}

void write_uint8(hid_t parent, const std::string& name, const std::vector<std::uint8_t>& data, const std::string& units,
                 const std::string& description) {
  write_dataset(parent, name, H5T_STD_U8LE, H5T_NATIVE_UINT8, data.data(), {data.size()}, units, description);
}

void write_raw(hid_t parent, const std::string& name, hid_t type, const void* data, const std::vector<hsize_t>& dims,
               const std::string& units, const std::string& description, Storage storage) {
  write_dataset(parent, name, type, type, data, dims, units, description, storage);
}

std::vector<hsize_t> dataset_dims(hid_t parent, const std::string& name) {
  Handle ds = open_dataset(parent, name);
  Handle space(H5Dget_space(ds), &H5Sclose);
  return shape_of(parent, name, space);
}

void read_raw(hid_t parent, const std::string& name, hid_t mem_type, void* data) {
  Handle ds = open_dataset(parent, name);
  Handle space(H5Dget_space(ds), &H5Sclose);
  if (H5Sget_simple_extent_npoints(space) > 0 && H5Dread(ds, mem_type, H5S_ALL, H5S_ALL, H5P_DEFAULT, data) < 0)
    fail(parent, fmt::format("cannot read dataset '{}'", name));
}

std::vector<double> read_doubles(hid_t parent, const std::string& name, std::vector<hsize_t>* dims_out) {
  return read_dataset<double>(parent, name, H5T_NATIVE_DOUBLE, dims_out);
}

std::vector<std::int32_t> read_int32(hid_t parent, const std::string& name) {
  return read_dataset<std::int32_t>(parent, name, H5T_NATIVE_INT32, nullptr);
}

std::vector<std::uint8_t> read_uint8(hid_t parent, const std::string& name) {
  return read_dataset<std::uint8_t>(parent, name, H5T_NATIVE_UINT8, nullptr);
}

void set_attr(hid_t obj, const std::string& name, const std::string& value) { set_attr(obj, name, value.c_str()); }

void set_attr(hid_t obj, const std::string& name, const char* value) {
  replace_attr(obj, name);
  Handle type = string_type();
  Handle space(H5Screate(H5S_SCALAR), &H5Sclose);
  Handle a(H5Acreate2(obj, name.c_str(), type, space, H5P_DEFAULT, H5P_DEFAULT), &H5Aclose);
  if (a.get() < 0 || H5Awrite(a, type, &value) < 0) fail(obj, fmt::format("cannot write attribute '{}'", name));
}

void set_attr(hid_t obj, const std::string& name, double value) {
  set_scalar_attr(obj, name, H5T_IEEE_F64LE, H5T_NATIVE_DOUBLE, value);
}

void set_attr(hid_t obj, const std::string& name, long long value) {
  set_scalar_attr(obj, name, H5T_STD_I64LE, H5T_NATIVE_LLONG, value);
}

bool has_attr(hid_t obj, const std::string& name) { return H5Aexists(obj, name.c_str()) > 0; }

std::string get_attr_string(hid_t obj, const std::string& name) {
  Handle a = open_attr(obj, name);
  Handle ftype(H5Aget_type(a), &H5Tclose);
  if (H5Tget_class(ftype) != H5T_STRING) fail(obj, fmt::format("attribute '{}' is not a string", name));
  if (H5Tis_variable_str(ftype) > 0) {
    Handle mtype = string_type();
    char* s = nullptr;
    if (H5Aread(a, mtype, &s) < 0) fail(obj, fmt::format("cannot read attribute '{}'", name));
    std::string out = s ? s : "";
    H5free_memory(s);
    return out;
  }
  const std::size_t n = H5Tget_size(ftype);
  Handle mtype(H5Tcopy(H5T_C_S1), &H5Tclose);
  H5Tset_size(mtype, n + 1);
  std::string buf(n + 1, '\0');
  if (H5Aread(a, mtype, buf.data()) < 0) fail(obj, fmt::format("cannot read attribute '{}'", name));
  buf.resize(std::char_traits<char>::length(buf.c_str()));
  return buf;
}

double get_attr_double(hid_t obj, const std::string& name) {
  Handle a = open_attr(obj, name);
  double v = 0;
  if (H5Aread(a, H5T_NATIVE_DOUBLE, &v) < 0) fail(obj, fmt::format("cannot read attribute '{}' as a number", name));
  return v;
}

long long get_attr_int(hid_t obj, const std::string& name) {
  Handle a = open_attr(obj, name);
  long long v = 0;
  if (H5Aread(a, H5T_NATIVE_LLONG, &v) < 0) fail(obj, fmt::format("cannot read attribute '{}' as an integer", name));
  return v;
}

std::string dataset_units(hid_t parent, const std::string& name) {
  Handle ds = open_dataset(parent, name);
  return has_attr(ds, "units") ? get_attr_string(ds, "units") : std::string();
}

}  // namespace gravsweep::results::h5
