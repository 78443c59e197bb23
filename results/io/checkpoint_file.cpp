#include "results/io/checkpoint_file.h"

#include <fcntl.h>
#include <fmt/format.h>
#include <unistd.h>

#include <cmath>
#include <cstring>
#include <limits>
#include <type_traits>

#include "results/io/hdf5.h"

namespace gravsweep::results {

namespace {

static_assert(sizeof(Vec3) == 3 * sizeof(double), "Vec3 arrays are written as (N, 3) doubles");
static_assert(sizeof(FrameHistory) == 7 * sizeof(double), "FrameHistory has no padding: hashed as raw bytes");
static_assert(sizeof(bool) == 1 && sizeof(SizeClass) == 1, "flags and size classes are stored as uint8");

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

h5::Handle copy_type(hid_t t) { return h5::Handle(H5Tcopy(t), &H5Tclose); }

h5::Handle vec3_type() {
  const hsize_t three = 3;
  return h5::Handle(H5Tarray_create2(H5T_NATIVE_DOUBLE, 1, &three), &H5Tclose);
}

template <class T>
struct Rec {
  static_assert(std::is_same_v<T, double> || std::is_same_v<T, Vec3> || std::is_same_v<T, std::uint32_t> ||
                std::is_same_v<T, std::uint8_t> || std::is_same_v<T, SizeClass>);
  static h5::Handle type() {
    if constexpr (std::is_same_v<T, std::uint32_t>)
      return copy_type(H5T_NATIVE_UINT32);
    else if constexpr (std::is_same_v<T, std::uint8_t> || std::is_same_v<T, SizeClass>)
      return copy_type(H5T_NATIVE_UINT8);
    else
      return copy_type(H5T_NATIVE_DOUBLE);  // double, and Vec3 as three columns
  }
  static constexpr hsize_t width = std::is_same_v<T, Vec3> ? 3 : 1;
  static void hash(ContentHash& h, const std::vector<T>& v) { h.bytes(v.data(), v.size() * sizeof(T)); }
};

template <>
struct Rec<ContactHistory> {
  static h5::Handle type() {
    const ContactHistory r;
    h5::Handle t(H5Tcreate(H5T_COMPOUND, sizeof r), &H5Tclose);
    H5Tinsert(t, "shear_m", offset_in(r, r.shear_m), vec3_type());
    H5Tinsert(t, "duration_s", offset_in(r, r.duration_s), H5T_NATIVE_DOUBLE);
    H5Tinsert(t, "gate_s", offset_in(r, r.gate_s), H5T_NATIVE_DOUBLE);
    H5Tinsert(t, "active", offset_in(r, r.active), H5T_NATIVE_UINT8);
    return t;
  }
  static constexpr hsize_t width = 1;
  static void hash(ContentHash& h, const std::vector<ContactHistory>& v) {
    for (const ContactHistory& r : v) {
      std::uint8_t active = 0;
      std::memcpy(&active, &r.active, 1);  // the stored byte, even one that is not a valid bool
      h.value(r.shear_m), h.value(r.duration_s), h.value(r.gate_s), h.value(active);
    }
  }
};

template <>
struct Rec<FrameHistory> {
  static h5::Handle type() {
    const FrameHistory r;
    h5::Handle t(H5Tcreate(H5T_COMPOUND, sizeof r), &H5Tclose);
    H5Tinsert(t, "n_old", offset_in(r, r.n_old), vec3_type());
    H5Tinsert(t, "roll_rad", offset_in(r, r.roll_rad), vec3_type());
    H5Tinsert(t, "twist_rad", offset_in(r, r.twist_rad), H5T_NATIVE_DOUBLE);
    return t;
  }
  static constexpr hsize_t width = 1;
  static void hash(ContentHash& h, const std::vector<FrameHistory>& v) { h.bytes(v.data(), v.size() * sizeof(v[0])); }
};

template <>
struct Rec<DropSample> {
  static h5::Handle type() {
    const DropSample r;
    h5::Handle t(H5Tcreate(H5T_COMPOUND, sizeof r), &H5Tclose);
    H5Tinsert(t, "t_s", offset_in(r, r.t_s), H5T_NATIVE_DOUBLE);
    H5Tinsert(t, "depth_m", offset_in(r, r.depth_m), H5T_NATIVE_DOUBLE);
    H5Tinsert(t, "velocity_down_m_s", offset_in(r, r.velocity_down_m_s), H5T_NATIVE_DOUBLE);
    H5Tinsert(t, "accel_up_m_s2", offset_in(r, r.accel_up_m_s2), H5T_NATIVE_DOUBLE);
    H5Tinsert(t, "omega_rad_s", offset_in(r, r.omega_rad_s), vec3_type());
    H5Tinsert(t, "position_m", offset_in(r, r.position_m), vec3_type());
    H5Tinsert(t, "contacts", offset_in(r, r.contacts), H5T_NATIVE_INT);
    H5Tinsert(t, "grain_kinetic_energy_J", offset_in(r, r.grain_kinetic_energy_J), H5T_NATIVE_DOUBLE);
    return t;
  }
  static constexpr hsize_t width = 1;
  static void hash(ContentHash& h, const std::vector<DropSample>& v) {
    for (const DropSample& s : v) {
      h.value(s.t_s), h.value(s.depth_m), h.value(s.velocity_down_m_s), h.value(s.accel_up_m_s2);
      h.value(s.omega_rad_s), h.value(s.position_m), h.value(s.contacts), h.value(s.grain_kinetic_energy_J);
    }
  }
};

/// Writes what visit() shows it, hashing every value.
struct Writer {
  static constexpr bool kReading = false;
  ContentHash hash;
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
    h5::write_raw(g, name, Rec<T>::type(), v.data(), dims, units, description);
    Rec<T>::hash(hash, v);
  }
};

/// Reads what visit() asks for, hashing every value as the writer did.
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
      throw CheckpointError(fmt::format("{}/{}: shape of rank {}, expected (N{})", h5::where(g), name, dims.size(),
                                        Rec<T>::width > 1 ? ", 3" : ""));
    v.resize(static_cast<std::size_t>(dims[0]));
    h5::read_raw(g, name, Rec<T>::type(), v.data());
    Rec<T>::hash(hash, v);
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

template <class Io>
void visit_particles(Io& io, hid_t root, Particles& p) {
  h5::Handle g = io.group(root, "particles");
  io.array(g, "position_m", p.position_m, "m", "particle centres, engine frame (z up)");
  io.array(g, "velocity_m_s", p.velocity_m_s, "m/s", "");
  io.array(g, "omega_rad_s", p.omega_rad_s, "rad/s", "");
  io.array(g, "eval_velocity_m_s", p.eval_velocity_m_s, "m/s", "velocities the force evaluation reads");
  io.array(g, "eval_omega_rad_s", p.eval_omega_rad_s, "rad/s", "angular velocities the force evaluation reads");
  io.array(g, "force_N", p.force_N, "N", "forces of the last evaluation, gravity included");
  io.array(g, "torque_N_m", p.torque_N_m, "N m", "torques of the last evaluation");
  io.array(g, "radius_m", p.radius_m, "m", "");
  io.array(g, "mass_kg", p.mass_kg, "kg", "");
  io.array(g, "inv_mass_1_kg", p.inv_mass_1_kg, "1/kg", "0 for a fixed particle");
  io.array(g, "inv_inertia_1_kg_m2", p.inv_inertia_1_kg_m2, "1/(kg m2)", "0 for a fixed particle");
  io.array(g, "material", p.material, "1", "material id");
  io.array(g, "size_class", p.size_class, "1", "0 grain, 1 projectile");
}

template <class Io>
void visit_lists(Io& io, hid_t root, SystemState& s) {
  h5::Handle nl = io.group(root, "neighbor_list");
  io.array(nl, "offset", s.list_offset, "1", "CSR row starts: pairs of particle i are [offset[i], offset[i+1])");
  io.array(nl, "neighbor", s.list_neighbor, "1", "partner j > i of each listed pair");
  io.array(nl, "work_offset", s.list_work_offset, "1", "pair-loop work before each row (thread split)");
  io.array(nl, "history", s.pair_history, "", "contact history of each listed pair");
  io.array(nl, "frame_history", s.pair_frame_history, "", "frame history of each listed pair (hooke, zhang)");
  io.array(nl, "position_at_build_m", s.position_at_build_m, "m", "positions at the last list build");
  h5::Handle w = io.group(root, "walls");
  io.array(w, "candidates", s.wall_candidates, "1", "particle * walls + wall, increasing");
  io.array(w, "history", s.wall_history, "", "contact history of each candidate");
  io.array(w, "frame_history", s.wall_frame_history, "", "frame history of each candidate (hooke, zhang)");
}

template <class Io>
void visit_system(Io& io, hid_t root, SystemState& s) {
  h5::Handle g = io.group(root, "system");
  io.attr(g, "time_s", s.time_s);
  io.attr(g, "step", s.step);
  io.attr(g, "skin_m", s.skin_m);
  io.attr(g, "list_builds", s.list_builds);
  number(io, g, "wall_count_at_build", s.wall_count_at_build);
  number(io, g, "initialized", s.initialized);
  number(io, g, "rebuild_due", s.rebuild_due);
  number(io, g, "have_step_checks", s.have_step_checks);
  number(io, g, "have_forces", s.have_forces);
  io.attr(g, "contacts", s.stats.contacts);
  io.attr(g, "wall_contacts", s.stats.wall_contacts);
  io.attr(g, "elastic_energy_J", s.stats.elastic_energy_J);
  std::vector<Vec3> gravity{s.gravity_m_s2}, domain;
  if (s.domain) domain = {s.domain->lo_m, s.domain->hi_m};
  io.array(g, "gravity_m_s2", gravity, "m/s2", "gravity, engine frame");
  io.array(g, "domain_m", domain, "m", "domain corners lo, hi (no rows: no domain)");
  if constexpr (Io::kReading) {
    if (gravity.size() != 1 || (!domain.empty() && domain.size() != 2))
      throw CheckpointError(fmt::format("{}: gravity_m_s2 has {} rows (expected 1), domain_m {} (expected 0 or 2)",
                                        h5::where(g), gravity.size(), domain.size()));
    s.gravity_m_s2 = gravity[0];
    s.domain = domain.empty() ? std::nullopt : std::optional<Domain>(Domain{domain[0], domain[1]});
  }
  visit_particles(io, root, s.particles);
  visit_lists(io, root, s);
}

template <class Io>
void visit_loop(Io& io, hid_t root, DropLoopState& st) {
  h5::Handle g = io.group(root, "drop");
  DropResult& r = st.result;
  io.attr(g, "samples_done", st.samples_done);
  io.attr(g, "below_stop", st.below_stop);
  io.attr(g, "last_snapshot", st.last_snapshot);
  io.attr(g, "release_time_s", st.release_time_s);
  io.attr(g, "release_step", st.release_step);
  io.attr(g, "surface_height_m", r.surface_height_m);
  io.attr(g, "release_height_m", r.release_height_m);
  io.attr(g, "release_speed_m_s", r.release_speed_m_s);
  io.attr(g, "first_touch_height_m", r.first_touch_height_m);
  optional_time(io, g, "first_contact_s", r.first_contact_s);
  optional_time(io, g, "rest_s", r.rest_s);
  number(io, g, "stopped", r.stopped);
  io.attr(g, "steps", r.steps);
  number(io, g, "projectile", r.projectile);
  number(io, g, "grains_spilled", r.grains_spilled);
  io.array(g, "samples", r.samples, "", "the trace so far, one record per sample (DropSample, paper frame)");
}

template <class Io>
void visit_report(Io& io, hid_t g, BedReport& r) {
  number(io, g, "grains_placed", r.grains_placed);
  number(io, g, "grains_kept", r.grains_kept);
  io.attr(g, "settle_time_s", r.settle_time_s);
  io.attr(g, "relax_time_s", r.relax_time_s);
  io.attr(g, "quench_time_s", r.quench_time_s);
  io.attr(g, "surface_relax_s", r.surface_relax_s);
  number(io, g, "settled", r.settled);
  number(io, g, "settle_end", r.settle_end);
  number(io, g, "relax_end", r.relax_end);
  io.attr(g, "rms_speed_m_s", r.rms_speed_m_s);
  io.attr(g, "max_speed_m_s", r.max_speed_m_s);
  io.attr(g, "surface_height_m", r.surface_height_m);
  io.attr(g, "bulk_density_kg_m3", r.bulk_density_kg_m3);
}

template <class Io>
void visit_bed_loop(Io& io, hid_t root, BedLoopState& st) {
  h5::Handle g = io.group(root, "bed");
  number(io, g, "stage", st.stage);
  if constexpr (Io::kReading) {
    if (static_cast<int>(st.stage) > static_cast<int>(BedStage::relax))
      throw CheckpointError(
          fmt::format("{}: stage {} is not a stage of a bed's preparation", h5::where(g), static_cast<int>(st.stage)));
  }
  io.attr(g, "intervals", st.cursor.intervals);
  io.attr(g, "stage_start_s", st.cursor.start_s);
  io.attr(g, "low_m_s", st.cursor.low_m_s);
  io.attr(g, "low_at_s", st.cursor.low_at_s);
  io.attr(g, "ramp_from_m_s2", st.cursor.from_m_s2);
  io.attr(g, "wall_height_m", st.wall_height_m);
  visit_report(io, g, st.report);
}

template <class Io>
void visit(Io& io, hid_t root, CheckpointData& c) {
  std::string kind = c.kind();
  io.attr(root, "kind", kind);
  if constexpr (Io::kReading) {
    if (kind == "bed")
      c.state = BedState{};
    else if (kind != "drop")
      throw CheckpointError(fmt::format("kind '{}' is neither 'drop' nor 'bed'", kind));
  }
  io.attr(root, "code_version", c.code_version);
  io.attr(root, "identity", c.identity_json);
  io.attr(root, "wall_time_s", c.wall_time_s);
  io.attr(root, "resumes", c.resumes);
  io.attr(root, "position_s", c.position_s);
  if (auto* d = std::get_if<DropState>(&c.state)) {
    visit_system(io, root, d->system);
    visit_loop(io, root, d->loop);
  } else {
    auto& b = std::get<BedState>(c.state);
    visit_system(io, root, b.system);
    visit_bed_loop(io, root, b.loop);
  }
}

/// fsync of a file or a folder; a failure is an error for a file, ignored for a folder.
void fsync_path(const std::filesystem::path& path, bool required) {
  const int fd = ::open(path.c_str(), O_RDONLY);
  const bool ok = fd >= 0 && ::fsync(fd) == 0;
  if (fd >= 0) ::close(fd);
  if (!ok && required) throw h5::H5Error(fmt::format("{}: fsync failed: {}", path.string(), std::strerror(errno)));
}

}  // namespace

void write_checkpoint(const std::filesystem::path& path, const CheckpointData& c) {
  h5::write_atomically(path, [&](const std::filesystem::path& tmp) {
    h5::File f = h5::File::create(tmp);
    h5::set_attr(f.id(), "format", kCheckpointFormat);
    h5::set_attr(f.id(), "format_version", kCheckpointFormatVersion);
    Writer w;
    visit(w, f.id(), const_cast<CheckpointData&>(c));  // the writer only reads the values
    h5::set_attr(f.id(), "content_hash", w.hash.hex());
    f.close();
    fsync_path(tmp, true);
  });
  fsync_path(path.parent_path().empty() ? std::filesystem::path(".") : path.parent_path(), false);
}

CheckpointData read_checkpoint(const std::filesystem::path& path) {
  try {
    h5::File f = h5::File::open_read(path);
    if (!h5::has_attr(f.id(), "format") || h5::get_attr_string(f.id(), "format") != kCheckpointFormat)
      throw CheckpointError(
          fmt::format("not a gravsweep checkpoint (root attribute format != '{}')", kCheckpointFormat));
    const long long version = h5::get_attr_int(f.id(), "format_version");
    if (version != kCheckpointFormatVersion)
      throw CheckpointError(
          fmt::format("format version {}, this build reads version {}", version, kCheckpointFormatVersion));
    CheckpointData c;
    Reader r;
    visit(r, f.id(), c);
    const std::string recorded = h5::get_attr_string(f.id(), "content_hash");
    if (recorded != r.hash.hex())
      throw CheckpointError(
          fmt::format("content hash {} of what was read differs from the recorded {}: the file "
                      "changed after it was written",
                      r.hash.hex(), recorded));
    return c;
  } catch (const std::exception& e) {
    throw CheckpointError(fmt::format("checkpoint {}: {}", path.string(), e.what()));
  }
}

}  // namespace gravsweep::results
