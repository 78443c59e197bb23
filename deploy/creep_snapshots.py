#!/usr/bin/python3
"""Where a bed creeps: per grain snapshot of `gravsweep run` (DIR/snapshots.h5), the RMS and the
fastest grain speed, the fastest surface grain (centre within 2 grain diameters of the surface)
and where it is (height z and distance r from the axis), and the fastest surface grain within
R of the axis (default 0.1 m, one projectile diameter: where the drops land).

    /usr/bin/python3 deploy/creep_snapshots.py DIR/snapshots.h5 [SURFACE_HEIGHT_M] [R_M]

SURFACE_HEIGHT_M defaults to the highest grain centre of the first snapshot."""
import sys

import h5py
import numpy as np

GRAIN_D_M = 0.01  # Table 1 glass beads


def main():
    path = sys.argv[1]
    r_max = float(sys.argv[3]) if len(sys.argv) > 3 else 0.1
    with h5py.File(path, "r") as f:
        snaps = [f["snapshots"][k] for k in sorted(f["snapshots"].keys()) if "grains" in f["snapshots"][k]]
        snaps.sort(key=lambda s: s.attrs["t_s"])
        surface = float(sys.argv[2]) if len(sys.argv) > 2 else snaps[0]["grains"]["position_m"][:, 2].max()
        print(f"{'t_s':>6} {'rms_m_s':>9} {'max_m_s':>9} {'max_surface_m_s':>15} {'at_z_m':>7} {'at_r_m':>7} "
              f"{'max_surface_r<' + format(r_max, 'g') + 'm_m_s':>22}")
        for s in snaps:
            x = s["grains"]["position_m"][:]
            v = np.linalg.norm(s["grains"]["velocity_m_s"][:], axis=1)
            r = np.hypot(x[:, 0], x[:, 1])
            top = x[:, 2] > surface - 2 * GRAIN_D_M
            near = top & (r < r_max)
            i = np.argmax(np.where(top, v, -1))
            print(f"{s.attrs['t_s']:6.2f} {np.sqrt((v ** 2).mean()):9.2e} {v.max():9.2e} {v[i]:15.2e} "
                  f"{x[i, 2]:7.3f} {r[i]:7.3f} {v[near].max() if near.any() else 0:22.2e}")


if __name__ == "__main__":
    main()
