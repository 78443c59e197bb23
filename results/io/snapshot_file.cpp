#include "results/io/snapshot_file.h"

#include <fmt/format.h>

#include <fstream>

#include "results/io/hdf5.h"

namespace gravsweep::results {

namespace {

std::string snapshot_group(std::size_t k) { return fmt::format("{:06d}", k); }

/// The fields of one point set: name, units, description, components (3 or 1).
struct PointField {
  const char* name;
  const char* units;
  const char* description;
  int components;
};
constexpr PointField kPointFields[] = {
    {"position_m", "m", "centre, engine frame (z up, bottom disk at z = 0, axis at x = y = 0)", 3},
    {"velocity_m_s", "m/s", "velocity, engine frame", 3},
    {"omega_rad_s", "rad/s", "angular velocity, engine frame", 3},
    {"contacts", "1", "grains and walls touching it", 1},
};

void write_points(hid_t parent, const std::string& name, const SnapshotPoints& p) {
  const std::size_t n = p.size();
  if (p.position_m.size() != 3 * n || p.velocity_m_s.size() != 3 * n || p.omega_rad_s.size() != 3 * n)
    throw h5::H5Error(fmt::format("{}/{}: inconsistent snapshot columns for {} points", h5::where(parent), name, n));
  h5::Handle g = h5::create_group(parent, name);
  const std::vector<hsize_t> dims{n, 3};
  // Contiguous: state doubles hardly compress (deflated, 26 snapshots of 2,034 grains kept 100 % of
  // their 155 kB each) and the deflate time is spent on every snapshot (BENCHMARKS.md).
  constexpr auto raw = h5::Storage::contiguous;
  h5::write_doubles(g, "position_m", p.position_m, dims, "m", kPointFields[0].description, raw);
  h5::write_doubles(g, "velocity_m_s", p.velocity_m_s, dims, "m/s", kPointFields[1].description, raw);
  h5::write_doubles(g, "omega_rad_s", p.omega_rad_s, dims, "rad/s", kPointFields[2].description, raw);
  h5::write_int32(g, "contacts", p.contacts, "1", kPointFields[3].description, raw);
}

SnapshotPoints read_points(hid_t parent, const std::string& name) {
  h5::Handle g = h5::open_group(parent, name);
  SnapshotPoints p;
  p.position_m = h5::read_doubles(g, "position_m");
  p.velocity_m_s = h5::read_doubles(g, "velocity_m_s");
  p.omega_rad_s = h5::read_doubles(g, "omega_rad_s");
  p.contacts = h5::read_int32(g, "contacts");
  return p;
}

/// One XDMF point set: Polyvertex topology, XYZ geometry, the radius and the per-snapshot fields.
void xdmf_points(std::string& x, const std::string& h5, const std::string& name, std::size_t n, std::size_t k) {
  const std::string base = fmt::format("{}:/snapshots/{}/{}", h5, snapshot_group(k), name);
  auto item = [&](const std::string& dims, const char* type, int precision, const std::string& path) {
    return fmt::format("<DataItem Dimensions=\"{}\" NumberType=\"{}\" Precision=\"{}\" Format=\"HDF\">{}</DataItem>",
                       dims, type, precision, path);
  };
  x += fmt::format("        <Grid Name=\"{}\" GridType=\"Uniform\">\n", name);
  x += fmt::format("          <Topology TopologyType=\"Polyvertex\" NumberOfElements=\"{}\" NodesPerElement=\"1\"/>\n",
                   n);
  x += fmt::format("          <Geometry GeometryType=\"XYZ\">{}</Geometry>\n",
                   item(fmt::format("{} 3", n), "Float", 8, base + "/position_m"));
  x += fmt::format("          <Attribute Name=\"radius_m\" AttributeType=\"Scalar\" Center=\"Node\">{}</Attribute>\n",
                   item(std::to_string(n), "Float", 8, fmt::format("{}:/{}/radius_m", h5, name)));
  for (const auto& f : kPointFields) {
    if (std::string(f.name) == "position_m") continue;
    const bool vec = f.components == 3;
    x += fmt::format("          <Attribute Name=\"{}\" AttributeType=\"{}\" Center=\"Node\">{}</Attribute>\n", f.name,
                     vec ? "Vector" : "Scalar",
                     vec ? item(fmt::format("{} 3", n), "Float", 8, base + "/" + f.name)
                         : item(std::to_string(n), "Int", 4, base + "/" + f.name));
  }
  x += "        </Grid>\n";
}

}  // namespace

std::filesystem::path snapshot_path_for(const std::filesystem::path& trace_path) {
  if (trace_path.filename() == "trace.h5") return trace_path.parent_path() / "snapshots.h5";
  auto p = trace_path;
  p.replace_extension(".snapshots.h5");
  return p;
}

struct SnapshotWriter::Impl {
  std::filesystem::path final_path, tmp_path;
  h5::File file;
  h5::Handle snapshots;
  std::size_t grains = 0;
  bool finished = false;
};

SnapshotWriter::SnapshotWriter(const std::filesystem::path& h5_path, const std::vector<double>& grain_radius_m,
                               double projectile_radius_m, double interval_s, const std::string& code_version)
    : impl_(std::make_unique<Impl>()) {
  impl_->final_path = h5_path;
  impl_->tmp_path = h5::temporary_sibling(h5_path);
  impl_->grains = grain_radius_m.size();
  impl_->file = h5::File::create(impl_->tmp_path, h5::Backing::streaming);
  const hid_t f = impl_->file.id();
  h5::set_attr(f, "format", kSnapshotFormat);
  h5::set_attr(f, "format_version", kSnapshotFormatVersion);
  h5::set_attr(f, "code_version", code_version);
  h5::set_attr(f, "interval_s", interval_s);
  h5::set_attr(f, "grains", static_cast<long long>(impl_->grains));
  {
    h5::Handle g = h5::create_group(f, "grains");
    h5::write_doubles(g, "radius_m", grain_radius_m, {impl_->grains}, "m", "grain radius, in the order of bed.h5");
  }
  {
    h5::Handle g = h5::create_group(f, "projectile");
    h5::write_doubles(g, "radius_m", {projectile_radius_m}, {1}, "m", "projectile radius");
  }
  impl_->snapshots = h5::create_group(f, "snapshots");
}

SnapshotWriter::~SnapshotWriter() {
  if (impl_ && !impl_->finished) {
    impl_->snapshots.reset();
    impl_->file = h5::File();
    std::error_code ec;
    std::filesystem::remove(impl_->tmp_path, ec);
  }
}

void SnapshotWriter::append(const Snapshot& s) {
  if (s.grains.size() != impl_->grains || s.projectile.size() != 1)
    throw h5::H5Error(fmt::format("{}: snapshot of {} grains and {} projectiles, expected {} and 1",
                                  impl_->final_path.string(), s.grains.size(), s.projectile.size(), impl_->grains));
  h5::Handle g = h5::create_group(impl_->snapshots, snapshot_group(times_.size()));
  h5::set_attr(g, "t_s", s.t_s);
  write_points(g, "grains", s.grains);
  write_points(g, "projectile", s.projectile);
  times_.push_back(s.t_s);
}

std::size_t SnapshotWriter::bytes_per_snapshot() const {
  const std::size_t per_point = 3 * 3 * sizeof(double) + sizeof(std::int32_t);
  return (impl_->grains + 1) * per_point;
}

std::filesystem::path SnapshotWriter::finish() {
  h5::write_doubles(impl_->snapshots, "t_s", times_, {times_.size()}, "s", "time since release of each snapshot");
  h5::set_attr(impl_->file.id(), "snapshots", static_cast<long long>(times_.size()));
  impl_->snapshots.reset();
  impl_->file.close();
  std::filesystem::rename(impl_->tmp_path, impl_->final_path);
  impl_->finished = true;
  auto xdmf = impl_->final_path;
  xdmf.replace_extension(".xdmf");
  const auto xtmp = h5::temporary_sibling(xdmf);
  {
    std::ofstream f(xtmp);
    f << snapshot_xdmf(impl_->final_path.filename().string(), impl_->grains, times_);
    if (!f) throw h5::H5Error(fmt::format("{}: cannot write", xtmp.string()));
  }
  std::filesystem::rename(xtmp, xdmf);
  return xdmf;
}

std::string snapshot_xdmf(const std::string& h5, std::size_t grains, const std::vector<double>& t_s) {
  std::string x =
      "<?xml version=\"1.0\" ?>\n<!DOCTYPE Xdmf SYSTEM \"Xdmf.dtd\" []>\n<Xdmf Version=\"2.0\">\n  <Domain>\n"
      "    <Grid Name=\"drop\" GridType=\"Collection\" CollectionType=\"Temporal\">\n";
  for (std::size_t k = 0; k < t_s.size(); ++k) {
    x += fmt::format("      <Grid Name=\"snapshot {}\" GridType=\"Collection\" CollectionType=\"Spatial\">\n", k);
    x += fmt::format("        <Time Value=\"{:.9g}\"/>\n", t_s[k]);
    xdmf_points(x, h5, "grains", grains, k);
    xdmf_points(x, h5, "projectile", 1, k);
    x += "      </Grid>\n";
  }
  x += "    </Grid>\n  </Domain>\n</Xdmf>\n";
  return x;
}

std::vector<double> read_snapshot_times(const std::filesystem::path& path) {
  h5::File f = h5::File::open_read(path);
  if (!h5::has_attr(f.id(), "format") || h5::get_attr_string(f.id(), "format") != kSnapshotFormat)
    throw h5::H5Error(fmt::format("{}: not a gravsweep snapshots file (format attribute '{}' expected)", path.string(),
                                  kSnapshotFormat));
  h5::Handle g = h5::open_group(f.id(), "snapshots");
  return h5::read_doubles(g, "t_s");
}

Snapshot read_snapshot(const std::filesystem::path& path, long long k) {
  const std::vector<double> times = read_snapshot_times(path);
  if (times.empty()) throw h5::H5Error(fmt::format("{}: holds no snapshot", path.string()));
  const auto n = static_cast<long long>(times.size());
  if (k < 0) k = n - 1;
  if (k >= n) throw h5::H5Error(fmt::format("{}: snapshot {} asked, the file holds {}", path.string(), k, n));
  h5::File f = h5::File::open_read(path);
  h5::Handle g = h5::open_group(f.id(), "snapshots/" + snapshot_group(static_cast<std::size_t>(k)));
  Snapshot s;
  s.t_s = times[static_cast<std::size_t>(k)];
  s.grains = read_points(g, "grains");
  s.projectile = read_points(g, "projectile");
  return s;
}

}  // namespace gravsweep::results
