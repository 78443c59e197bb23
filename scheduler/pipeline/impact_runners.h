// The impact sweep kind (a sweep spec's "job": "impact"): a drop job per point waiting for a
// prepared bed per bed key, run on scheduler/pipeline/impact_job.h. Registered in job_kinds.cpp.
#pragma once
#include "scheduler/sweep/spec.h"
#include "scheduler/sweep/sweep_kind.h"

namespace gravsweep::pipeline {

/// Validates a sweep point once, at submit: the text its jobs store (StoredScenario: validated,
/// marked, with the point as written), its bed key (drops with equal keys share a bed) and what its
/// id is computed from (id_point: its defaults version where that changes what it runs).
sweep::PointCheckFn impact_point_check();
/// The kind: its planner (impact_point_check, a bed per key), its base check and the bed and
/// drop runners.
sweep::SweepKind impact_sweep_kind();

}  // namespace gravsweep::pipeline
