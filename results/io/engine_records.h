// The engine's state and a drop's result as the records of results/io's files, and back: the one
// place where engine arrays (engine frame: z up, the container's floor at z = 0) become a bed file's
// grains, a trace's columns or a snapshot's points. The scheduler's jobs call these and add the
// facts a file carries beyond the engine's state (scenario, keys, versions).
#pragma once
#include <cstddef>
#include <filesystem>

#include "engine/scenario/bed.h"
#include "engine/scenario/impact.h"
#include "engine/system/system.h"
#include "results/io/bed_file.h"
#include "results/io/job_reports.h"
#include "results/io/snapshot_file.h"
#include "results/io/trace_file.h"

namespace gravsweep::results {

/// The facts of a bed file that `sys` itself holds: its cylinder wall's height and the simulated
/// time; the facts of the preparation are the caller's. Its grains are `sys.particles` (write_bed).
BedFacts bed_facts_of(const System& sys);

/// Reads a saved bed into `sys`, which holds no particle yet and whose config holds the contact
/// parameters: its grains straight into the System's particles (bit-exact state, no contact
/// history; read_bed's checks and errors) and its container walls. Returns the bed's facts.
BedFacts load_bed(System& sys, const std::filesystem::path& bed);

/// The drop's record as a trace: the columns of its samples taken over as they are (moved, so the
/// values the engine wrote are the trace's own and none is copied; `dr.samples` is left empty):
/// the four that processing reads into the trial's trace, `raw`, the others into the record's
/// own; with its release facts and stop flag. The sample rate, a trial fact, is the samples' own
/// (`nominal_rate_hz` for a trace of one sample).
TraceData take_trace_columns(DropResult& dr, double nominal_rate_hz);

/// One grain snapshot: every particle before `projectile` as a grain (the bed's order), the
/// projectile as its own point set.
Snapshot snapshot_of(const System& sys, ParticleIndex projectile, double t_s);

/// The report of a prepared bed from the preparation's report and the bed's rest state;
/// `at_rest_for_impacts_above_m_s` infinite: none. The wall time and checkpoint counts are the job's.
BedSummary bed_summary_of(const System& sys, const BedReport& rep, const BedRestState& rest,
                          double at_rest_for_impacts_above_m_s);

}  // namespace gravsweep::results
