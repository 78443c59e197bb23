#include "results/io/checkpoint_file.h"

#include <fcntl.h>
#include <fmt/format.h>
#include <unistd.h>

#include <cmath>
#include <cstring>
#include <limits>
#include <type_traits>

#include "results/io/h5_visit.h"
#include "results/io/hdf5.h"

namespace gravsweep::results {

namespace h5visit {

static_assert(sizeof(Vec3) == 3 * sizeof(double), "Vec3 arrays are written as (N, 3) doubles");
static_assert(sizeof(FrameHistory) == 7 * sizeof(double), "FrameHistory has no padding: hashed as raw bytes");
static_assert(sizeof(bool) == 1 && sizeof(SizeClass) == 1, "flags and size classes are stored as uint8");

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

}  // namespace h5visit

namespace {

using namespace h5visit;

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

/// The trace so far under /drop/samples: DropSamples' columns as they are in memory.
template <class Io>
void visit_samples(Io& io, hid_t drop, DropSamples& s) {
  h5::Handle g = io.group(drop, "samples");
  io.array(g, "t_s", s.t_s, "s", "time since release");
  io.array(g, "depth_m", s.depth_m, "m", "depth of the projectile's lowest point below the surface, paper frame");
  io.array(g, "velocity_down_m_s", s.velocity_down_m_s, "m/s", "positive down");
  io.array(g, "accel_up_m_s2", s.accel_up_m_s2, "m/s2", "positive up, mean over the preceding sample interval");
  io.rows(g, "omega_rad_s", s.omega_rad_s, 3, "rad/s", "projectile angular velocity, engine frame");
  io.rows(g, "position_m", s.position_m, 3, "m", "projectile centre, engine frame");
  io.array(g, "contacts", s.contacts, "1", "grains and walls touching the projectile");
  io.array(g, "grain_kinetic_energy_J", s.grain_kinetic_energy_J, "J", "kinetic energy of the grains");
  if constexpr (Io::kReading) {
    if (!s.consistent())
      throw CheckpointError(fmt::format("{}: the sample columns differ in length ({} times)", h5::where(g), s.size()));
  }
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
  visit_samples(io, g, r.samples);
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
