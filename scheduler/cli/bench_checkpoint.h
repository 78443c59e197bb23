// `gravsweep bench --checkpoint-dir DIR`: what a drop checkpoint of a bed costs
// (results/io/checkpoint_file.h): bytes per grain, and the seconds to save, write (with fsync),
// read and verify, and restore it.
#pragma once
#include <cstddef>
#include <filesystem>

#include "engine/system/system.h"

namespace gravsweep::cli {

/// Checkpoints `sys` (a bed after some steps) with `samples` trace samples into DIR, reads it
/// back, restores it into a fresh System, and prints the figures; the file is removed.
void print_checkpoint_cost(const System& sys, const std::filesystem::path& dir, std::size_t samples);

}  // namespace gravsweep::cli
