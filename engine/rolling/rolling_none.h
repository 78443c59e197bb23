// `none`: no rolling or twisting resistance.
#pragma once
#include "engine/contact/contact.h"

namespace gravsweep {

struct RollingNone {
  static constexpr const char* name = "none";
  static constexpr const char* description = "no rolling or twisting resistance";
  /// Needs FrameHistory stored per contact (contact.h).
  static constexpr bool uses_frame_history = false;
  GRAVSWEEP_INLINE static void apply(const ContactGeometry&, const PairCoefficients&, const ContactOptions&,
                                     ContactHistory&, FrameHistory&, double, ContactForce&) {}
};

}  // namespace gravsweep
