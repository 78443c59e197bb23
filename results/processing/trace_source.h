// Where a trace comes from (results/processing/trace.h, results/measurements/trial.h).
#pragma once
#include <string>

namespace gravsweep::results {

/// A lab record has a sensor (noise and a constant bias to remove); a DEM record has none and
/// carries its own velocity and depth. Bias removal follows from this, never from the columns.
enum class TraceSource { lab, dem };
const char* to_string(TraceSource s);
/// "lab" or "dem"; throws std::invalid_argument otherwise.
TraceSource trace_source_of(const std::string& s);

}  // namespace gravsweep::results
