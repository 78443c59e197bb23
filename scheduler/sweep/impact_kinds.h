// The job kinds of an impact campaign, registered with the queue (queue/job_types.h): a bed
// preparation and a drop. The sweep plans them (spec.h); pipeline/ runs them.
#pragma once
#include "scheduler/queue/job_types.h"

namespace gravsweep::sweep {

/// A prepared bed (beds/<job>.h5): the input its drops wait for, not a row of the results table;
/// running alone, it takes the pool's idle threads.
queue::JobKind bed_kind();
/// One impact (traces/<job>.h5): a row of the results table, with a column per output: the
/// paper's metrics (results::metric_fields()), the DEM's figures (results::dem_figure_fields())
/// and metrics_error, why a trace could not be measured (pipeline/impact_job.cpp:run_drop_job).
queue::JobKind drop_kind();

}  // namespace gravsweep::sweep
