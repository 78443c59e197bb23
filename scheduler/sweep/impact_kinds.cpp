#include "scheduler/sweep/impact_kinds.h"

namespace gravsweep::sweep {

queue::JobKind bed_kind() {
  static const queue::JobKind kind = queue::register_kind({"bed", "beds", ".h5", false, true});
  return kind;
}

queue::JobKind drop_kind() {
  static const queue::JobKind kind = queue::register_kind({"drop", "traces", ".h5", true, false});
  return kind;
}

namespace {
/// Registered when the program starts (before any campaign is opened), in this order, so that a
/// worker that only claims jobs knows both names and the files root knows both folders.
[[maybe_unused]] const bool kRegistered = (bed_kind(), drop_kind(), true);
}  // namespace

}  // namespace gravsweep::sweep
