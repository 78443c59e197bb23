// Exact Poncelet kinematics (Sunday et al. 2021 Eqs. 2-4, docs/physics/force-laws.md section 2.3 A)
// for the results/ tests: apeak, zstop and tstop in closed form, the state at any time after
// contact.
#pragma once
#include <cmath>

namespace gravsweep::testing {

struct Poncelet {
  double g = 9.81, m = 1.0, f0 = 25.0, inv_d1 = 25.0, v0 = 0.8;
  double A() const { return f0 / m - g; }
  double d1() const { return 1.0 / inv_d1; }
  double zstop() const { return 0.5 * d1() * std::log(1.0 + v0 * v0 / (A() * d1())); }
  double tstop() const { return std::sqrt(d1() / A()) * std::atan(v0 / std::sqrt(A() * d1())); }
  double apeak() const { return A() + v0 * v0 / d1(); }
  /// Upward acceleration tc seconds after contact (free fall before, rest after).
  double accel_up(double tc) const {
    if (tc < 0) return -g;
    if (tc >= tstop()) return 0.0;
    double v, z;
    state(tc, v, z);
    return A() + v * v * inv_d1;
  }
  /// Exact velocity (down) and depth tc seconds after contact (free fall before; rest after).
  void state(double tc, double& v, double& z) const {
    if (tc < 0) {
      v = v0 + g * tc;
      z = v0 * tc + 0.5 * g * tc * tc;
      return;
    }
    if (tc > tstop()) tc = tstop();
    const double th0 = std::atan(v0 / std::sqrt(A() * d1()));
    const double ph = th0 - tc * std::sqrt(A() / d1());
    v = std::sqrt(A() * d1()) * std::tan(ph);
    z = d1() * std::log(std::cos(ph) / std::cos(th0));
  }
};

}  // namespace gravsweep::testing
