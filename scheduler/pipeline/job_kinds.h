// The table of the sweep kinds gravsweep is built with (sweep/sweep_kind.h). The queue's no-op
// kind is the sweep registry's own; every kind that runs physics is one row here.
#pragma once

namespace gravsweep::pipeline {

/// Registers the built-in kinds with the sweep registry (once per process; later calls do
/// nothing). The CLI calls it at start, before any spec is expanded or worker runs.
void register_job_kinds();

}  // namespace gravsweep::pipeline
