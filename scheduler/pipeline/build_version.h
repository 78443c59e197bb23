// The code version recorded in bed.h5/trace.h5 and campaigns and printed by `--version`:
// "<project version>+<git describe>". It lives in one generated file (build_version.cpp.in) so
// that a new commit recompiles that file only, not every file that prints the version.
#pragma once
#include <string_view>

namespace gravsweep::pipeline {

/// e.g. "0.1.0+5206fb8938b1" ("+unknown" outside a git checkout).
const char* build_version();

/// True for a code version built from a source tree with uncommitted changes (`git describe
/// --dirty` appends "-dirty").
inline bool is_dirty_build(std::string_view code_version) { return code_version.ends_with("-dirty"); }

}  // namespace gravsweep::pipeline
