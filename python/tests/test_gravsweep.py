"""The Python package against the real binary: exported datasets, a campaign run here, and the
model verbs (run by CTest: `ctest -R Python`, or `python3 -m pytest python/tests`)."""
import json
import math
from pathlib import Path

import pytest

import gravsweep

REPO = Path(__file__).resolve().parents[2]
SWEEP = REPO / "data" / "gravity_sweep"
LAW = REPO / "examples" / "mission" / "law.json"


def test_an_exported_dataset_reads_as_data_frames_with_units_in_the_names():
    ds = gravsweep.open_dataset(REPO / "data" / "projectile_sweep" / "g9.81_d10cm")
    r = ds.results()
    assert len(r) == 18
    for col in ("zstop_m", "tstop_s", "vc_m_s", "apeak_m_s2", "projectile_mass_kg"):
        assert col in r.columns
    assert sorted(r.projectile_mass_kg.unique()) == [0.5, 1.0, 2.0]
    tr = ds.trace(ds.trials().trial_id.iloc[0])
    assert list(tr.columns[:2]) == ["t_s", "accel_m_s2"]
    assert tr.t_s.is_monotonic_increasing and len(tr) > 100


def test_a_missing_folder_or_trial_is_a_clear_error():
    with pytest.raises(gravsweep.GravsweepError, match="no trials.csv"):
        gravsweep.open_dataset(REPO / "no-such-folder")
    with pytest.raises(KeyError, match="no trial"):
        gravsweep.open_dataset(SWEEP / "g9.81").trace("nope")


def test_a_campaign_run_here_gives_its_status_results_and_trace(tmp_path):
    spec = json.loads((REPO / "examples" / "sweep_tiny.json").read_text())
    spec.pop("$schema")
    spec["axes"] = [{"name": "impact_speed_m_s", "pointer": "/projectile/impact_speed_m_s", "values": [1.0]}]
    spec["repeats"]["count"] = 1  # one bed job and one drop
    (tmp_path / "one.json").write_text(json.dumps(spec))
    db = tmp_path / "c.db"
    gravsweep.run_cli(["submit", tmp_path / "one.json", "--db", db])
    c = gravsweep.open_campaign(db)
    assert c.counts().queued.sum() + c.counts().waiting.sum() == 2
    gravsweep.run_cli(["work", "--db", db, "--threads", "1", "--quiet"])
    assert c.counts().done.sum() == 2
    r = c.results()
    drops = r[r.kind == "drop"] if "kind" in r.columns else r
    assert len(drops) == 1
    assert drops.zstop_m.iloc[0] > 0
    tr = c.trace(drops.job_id.iloc[0])
    assert {"t_s", "accel_up_m_s2", "velocity_down_m_s", "depth_m"} <= set(tr.columns)
    assert math.isclose(tr.attrs["gravity_m_s2"], 9.81)
    assert tr.depth_m.max() == pytest.approx(drops.zstop_m.iloc[0], rel=0.2)


def test_metrics_are_each_drops_own_scales_and_the_sweep_collapses():
    folders = [SWEEP / "g9.81", SWEEP / "g0.001"]
    own = gravsweep.metrics(folders)
    fixed = gravsweep.metrics(folders, time_scale="fixed")
    assert len(own) == len(fixed) == 12
    assert {"trial_id", "gravity_m_s2", "vc_m_s", "zstop_mm", "tstop_ms", "apeak_m_s2"} <= set(own.columns)
    at_1g = own.gravity_m_s2 == 9.81
    # The processing is the paper's at 1 g and differs only below it.
    assert (own[at_1g].tstop_ms.values == fixed[at_1g].tstop_ms.values).all()
    assert (own[~at_1g].apeak_m_s2.values != fixed[~at_1g].apeak_m_s2.values).any()
    c = gravsweep.collapse([SWEEP / f for f in ("g9.81", "g1.62", "g0.1", "g0.1_axis", "g0.01", "g0.01_axis",
                                                 "g0.001", "g0.001_axis")])
    assert list(c.metric) == ["zstop_over_D", "tstop_sqrt_g_over_D", "apeak_over_g"]
    assert (c.level_p > 0.01).all()  # GRAVITY.md: all three collapse in the drops' own scales


def test_fit_predict_and_infer_through_the_cli():
    f = gravsweep.fit([SWEEP / "g9.81", SWEEP / "g0.1"], model="scaled_base+gravity_depth_friction",
                      baseline="scaled_base")
    assert set(f["parameters"].parameter) == {"scaled_base.phi", "scaled_base.inv_d1_1_m",
                                             "gravity_depth_friction.kappa_kg_m"}
    assert (f["errors"].model == "scaled_base+gravity_depth_friction").any()
    r = gravsweep.rank([SWEEP / "g9.81", SWEEP / "g0.1"], baseline="scaled_base")  # one JSON document
    assert r["baseline"] == "scaled_base" and r["verdict"]
    assert {"round", "rank", "term", "p_signed_rank", "significant"} <= set(r["candidates"].columns)
    assert "depth_m" in set(r["residual_axes"].axis)
    p = gravsweep.predict(LAW, gravity=[1.62, 0.01], speed=0.3)
    assert list(p.range) == ["inside", "inside"]
    assert (p.zstop_lo_m < p.zstop_m).all() and (p.zstop_m < p.zstop_hi_m).all()
    with pytest.raises(gravsweep.GravsweepError) as e:
        gravsweep.predict(LAW, gravity=1e-7, speed=0.001)
    assert e.value.code == 2
    i = gravsweep.infer(LAW, gravity=1.62, speed=0.3, zstop=0.04, tstop=0.3)
    assert len(i["constants"]) == 4
    assert "yes" in set(i["constants"].constrained)
