// The job kinds of an impact campaign, registered with the queue (queue/job_types.h): a bed
// preparation and a drop. The sweep plans them (spec.h); pipeline/ runs them. A drop's outputs
// are declared and reported from the same field tables (DropOutputs).
#pragma once
#include "results/io/job_reports.h"
#include "results/processing/trace.h"
#include "scheduler/queue/job_types.h"
#include "scheduler/queue/run_output.h"

namespace gravsweep::sweep {

/// A prepared bed (beds/<job>.h5): the input its drops wait for, not a row of the results table;
/// running alone, it takes the pool's idle threads.
queue::JobKind bed_kind();
/// One impact (traces/<job>.h5): a row of the results table, with a column per output: the
/// paper's metrics (results::metric_fields()), the DEM's figures (results::dem_figure_fields())
/// and metrics_error, why a trace could not be measured (pipeline/impact_job.cpp:run_drop_job).
queue::JobKind drop_kind();

/// A drop's outputs as its runner reports them (queue::RunOutput::record): the drop's own record
/// (results::DropRecord: the trace record, which is the trial with the paper's metrics as processing
/// made them in it, and the engine's result, owned by move, and the run's facts), read by the tables that declare
/// drop_kind()'s outputs (metric_fields(), dem_figure_fields()) where a value is needed.
struct DropOutputs final : queue::OutputRecord, results::DropRecord {
  void each_output(const Visit& visit) const override;
};

}  // namespace gravsweep::sweep
