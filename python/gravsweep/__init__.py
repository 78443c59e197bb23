"""gravsweep from Python: campaigns, exported datasets and the model verbs.

    import gravsweep
    ds = gravsweep.open_dataset("data/gravity_sweep/g0.1")       # an exported dataset or a lab campaign
    ds.results()                                                 # pandas DataFrame, units in the names
    ds.trace(ds.trials().trial_id[0])                            # t_s, accel_m_s2, ... of one drop
    c = gravsweep.open_campaign("runs/sweep.db")                 # a campaign database (or postgresql://...)
    c.counts(), c.status()["eta_s"], c.results(where="gravity_m_s2<1"), c.trace(job_id)
    gravsweep.metrics(["data/gravity_sweep/g9.81", "data/gravity_sweep/g0.1"])  # each drop processed in its own scales
    gravsweep.collapse([...])                                     # the Froude collapse's verdict per metric
    gravsweep.fit(["data/gravity_sweep/g9.81"], model="scaled_base+gravity_depth_friction")
    gravsweep.predict("law.json", gravity=0.01, speed=0.2)

Everything goes through the `gravsweep` binary and its JSON or CSV output (the one
implementation of every verb; no compiled module to keep in step with the C++ build). The binary
is $GRAVSWEEP_BIN, else the repository's build/scheduler/gravsweep, else `gravsweep` on the PATH.
Formats: docs/formats/ (datasets), results/io/README.md (trace.h5).
"""
from __future__ import annotations

import io
import json
import os
import shutil
import subprocess
from pathlib import Path
from typing import Iterable, Sequence

import pandas as pd

__all__ = ["GravsweepError", "binary", "open_campaign", "open_dataset", "Campaign", "Dataset",
           "metrics", "collapse", "fit", "rank", "predict", "infer", "run_cli"]

_REPO = Path(__file__).resolve().parents[2]


class GravsweepError(RuntimeError):
    """A gravsweep command failed: its exit code and its message (stderr)."""

    def __init__(self, args: Sequence[str], code: int, stderr: str):
        self.code = code
        self.stderr = stderr
        super().__init__(f"gravsweep {' '.join(args)}: exit {code}: {stderr.strip()[-2000:]}")


def binary() -> str:
    """The gravsweep binary this package drives."""
    env = os.environ.get("GRAVSWEEP_BIN")
    if env:
        return env
    built = _REPO / "build" / "scheduler" / "gravsweep"
    if built.exists():
        return str(built)
    found = shutil.which("gravsweep")
    if found:
        return found
    raise GravsweepError(["--version"], 127, "no gravsweep binary: set GRAVSWEEP_BIN or build the repository")


def run_cli(args: Sequence[str], cwd: str | os.PathLike | None = None) -> str:
    """Runs `gravsweep ARGS...` and returns its stdout; GravsweepError on a non-zero exit."""
    p = subprocess.run([binary(), *map(str, args)], capture_output=True, text=True, cwd=cwd)
    if p.returncode != 0:
        raise GravsweepError(list(map(str, args)), p.returncode, p.stderr)
    return p.stdout


def _json_documents(text: str) -> list:
    """The JSON documents printed one after another (a verb may print several tables)."""
    dec, docs, i = json.JSONDecoder(), [], 0
    while True:
        while i < len(text) and text[i].isspace():
            i += 1
        if i >= len(text):
            return docs
        doc, i = dec.raw_decode(text, i)
        docs.append(doc)


def _trace_frame_h5(path: Path) -> pd.DataFrame:
    """A DEM drop's trace.h5 (results/io/README.md) as a DataFrame, columns with units."""
    import h5py
    with h5py.File(path, "r") as f:
        g = f["trace"]
        cols = {k: g[k][()] for k in ("t_s", "accel_up_m_s2", "velocity_down_m_s", "depth_m") if k in g}
        frame = pd.DataFrame(cols)
        frame.attrs.update({k: (v.item() if hasattr(v, "item") else v) for k, v in g.attrs.items()})
    return frame


class Dataset:
    """An exported dataset or a lab campaign folder: trials.csv, traces/, results.csv when exported."""

    def __init__(self, folder: str | os.PathLike):
        self.folder = Path(folder)
        if not (self.folder / "trials.csv").exists():
            raise GravsweepError(["open_dataset", str(folder)], 2,
                                 f"{folder}: no trials.csv (an exported dataset or a lab campaign folder)")

    def trials(self) -> pd.DataFrame:
        """trials.csv: one row per trial (the trial's set-up and processing, units in the names)."""
        return pd.read_csv(self.folder / "trials.csv")

    def results(self) -> pd.DataFrame:
        """The metrics of every trial: results.csv of an export, else trials.csv."""
        r = self.folder / "results.csv"
        return pd.read_csv(r) if r.exists() else self.trials()

    def trace(self, trial_id: str) -> pd.DataFrame:
        """One trial's record (t_s, accel_m_s2 and, for DEM drops, position_m and velocity_m_s)."""
        t = self.trials()
        row = t[t.trial_id.astype(str) == str(trial_id)]
        if row.empty:
            raise KeyError(f"{self.folder}: no trial {trial_id!r}")
        return pd.read_csv(self.folder / row.trace_file.iloc[0])

    def __repr__(self) -> str:
        return f"gravsweep.Dataset({str(self.folder)!r})"


class Campaign:
    """A campaign database (SQLite file or postgresql:// URL), read through the CLI."""

    def __init__(self, db: str | os.PathLike, files: str | os.PathLike | None = None):
        self.db = str(db)
        self.files = None if files is None else str(files)

    def _db_args(self) -> list[str]:
        return ["--db", self.db] + (["--files", self.files] if self.files else [])

    def status(self) -> dict:
        """`gravsweep status --format json`: counts by sweep and kind ("sweeps"), running jobs, ETA."""
        return json.loads(run_cli(["status", "--db", self.db, "--format", "json"]))

    def counts(self) -> pd.DataFrame:
        """Jobs by sweep and kind: waiting, queued, running, failed, done, dead."""
        return pd.DataFrame(self.status()["sweeps"])

    def results(self, where: str | Iterable[str] | None = None, sweep: str | None = None) -> pd.DataFrame:
        """Finished jobs with every column (`gravsweep results --format csv`), units in the names."""
        args = ["results", "--db", self.db, "--format", "csv"]
        for w in [where] if isinstance(where, str) else (where or []):
            args += ["--where", w]
        if sweep:
            args += ["--sweep", sweep]
        text = run_cli(args)
        return pd.read_csv(io.StringIO(text)) if text.strip() else pd.DataFrame()

    def trace(self, job_id: str) -> pd.DataFrame:
        """One drop's trace.h5: t_s, accel_up_m_s2, velocity_down_m_s, depth_m (attrs: its set-up)."""
        r = self.results(where=f"job_id={job_id}")
        if r.empty:
            raise KeyError(f"{self.db}: no finished drop {job_id!r}")
        path = Path(str(r.trace_path.iloc[0]))
        if not path.is_absolute():
            root = Path(self.files) if self.files else Path(self.db).with_suffix(".files")
            path = root / path
        return _trace_frame_h5(path)

    def __repr__(self) -> str:
        return f"gravsweep.Campaign({self.db!r})"


def open_dataset(folder: str | os.PathLike) -> Dataset:
    return Dataset(folder)


def open_campaign(db_or_url: str | os.PathLike, files: str | os.PathLike | None = None) -> Campaign:
    return Campaign(db_or_url, files)


def _inputs(inputs) -> list[str]:
    if isinstance(inputs, (str, os.PathLike, Dataset, Campaign)):
        inputs = [inputs]
    out = []
    for x in inputs:
        out.append(x.folder if isinstance(x, Dataset) else x.db if isinstance(x, Campaign) else x)
    return [str(x) for x in out]


def _processing_args(time_scale: str | None, end_rule: str | None) -> list[str]:
    return ((["--time-scale", time_scale] if time_scale else []) + (["--end-rule", end_rule] if end_rule else []))


def metrics(inputs, where: str | None = None, time_scale: str | None = None,
            end_rule: str | None = None) -> pd.DataFrame:
    """Every trial's metrics as the model verbs process it (`measurements import --format csv`):
    trial_id, source, gravity_m_s2, vc_m_s, apeak_m_s2, zstop_mm, tstop_ms, ... DEM drops in their
    own scales unless time_scale="fixed" (the paper's 500 Hz at every gravity); end_rule "speed"
    (default), "paper" or "depth". Nothing is written beside the inputs (a temporary database)."""
    import tempfile
    frames = []
    with tempfile.TemporaryDirectory() as tmp:
        for k, x in enumerate(_inputs(inputs)):
            args = ["measurements", "import", x, "--db", str(Path(tmp) / f"m{k}.db"), "--format", "csv"]
            args += _processing_args(time_scale, end_rule) + (["--where", where] if where else [])
            text = run_cli(args)
            if text.strip():
                frame = pd.read_csv(io.StringIO(text))
                frame.insert(0, "input", x)
                frames.append(frame)
    return pd.concat(frames, ignore_index=True) if frames else pd.DataFrame()


def collapse(inputs, where: str | None = None, time_scale: str | None = None,
             end_rule: str | None = None) -> pd.DataFrame:
    """`gravsweep model collapse --format json`: one row per scaled metric (zstop_over_D,
    tstop_sqrt_g_over_D, apeak_over_g) with the collapse ratio, the level and repeat scatter and
    the nested analysis of variance's F and p of the level effect at equal Froude number."""
    args = ["model", "collapse", *_inputs(inputs), "--format", "json"] + _processing_args(time_scale, end_rule)
    if where:
        args += ["--where", where]
    return pd.DataFrame(_json_documents(run_cli(args))[0])


def fit(inputs, model: str, baseline: str | None = None, where: str | None = None, **options) -> dict:
    """`gravsweep model fit`: {'parameters': DataFrame, 'errors': DataFrame} (held-out errors; and
    'projectiles' with leave_out="projectile")."""
    args = ["model", "fit", *_inputs(inputs), "--model", model, "--no-plot", "--format", "json"]
    if baseline:
        args += ["--baseline", baseline]
    if where:
        args += ["--where", where]
    for k, v in options.items():
        args += [f"--{k.replace('_', '-')}", str(v)]
    doc = json.loads(run_cli(args))
    out = {"parameters": pd.DataFrame(doc["parameters"]), "errors": pd.DataFrame(doc["held_out_errors"])}
    if "projectiles_held_out" in doc:
        out["projectiles"] = pd.DataFrame(doc["projectiles_held_out"])
    return out


def rank(inputs, scaled: bool = False, where: str | None = None, baseline: str | None = None) -> dict:
    """`gravsweep model rank --format json`: {'baseline': str, 'residual_axes': DataFrame,
    'candidates': DataFrame (round, rank, term, mean_rel_improvement_pct, trials_better, trials,
    p_signed_rank, significant), 'verdict': str}."""
    args = ["model", "rank", *_inputs(inputs), "--format", "json"] + (["--scaled"] if scaled else [])
    if baseline:
        args += ["--baseline", baseline]
    if where:
        args += ["--where", where]
    doc = json.loads(run_cli(args))
    return {"baseline": doc["baseline"], "residual_axes": pd.DataFrame(doc["residual_axes"]),
            "candidates": pd.DataFrame(doc["candidates"]), "verdict": doc["verdict"]}


def predict(law: str | os.PathLike, gravity, speed, diameter: float = 0.1, mass: float = 1.0,
            extrapolate: bool = False) -> pd.DataFrame:
    """`gravsweep model predict`: one row per (gravity, speed) with 95 % intervals and the range flag."""
    gs = gravity if isinstance(gravity, (list, tuple)) else [gravity]
    vs = speed if isinstance(speed, (list, tuple)) else [speed]
    args = ["model", "predict", "--law", str(law), "--gravity", *map(str, gs), "--speed", *map(str, vs),
            "--diameter", str(diameter), "--mass", str(mass), "--format", "json"]
    if extrapolate:
        args.append("--extrapolate")
    return pd.DataFrame(_json_documents(run_cli(args))[0])


def infer(law: str | os.PathLike, gravity: float, speed: float, zstop: float, tstop: float | None = None,
          apeak: float | None = None, diameter: float = 0.1, mass: float = 1.0) -> dict:
    """`gravsweep model infer`: {'constants': DataFrame, 'metrics': DataFrame, ...}."""
    args = ["model", "infer", "--law", str(law), "--gravity", str(gravity), "--speed", str(speed),
            "--zstop", str(zstop), "--diameter", str(diameter), "--mass", str(mass), "--format", "json"]
    if tstop is not None:
        args += ["--tstop", str(tstop)]
    if apeak is not None:
        args += ["--apeak", str(apeak)]
    doc = _json_documents(run_cli(args))[0]
    doc["constants"] = pd.DataFrame(doc["constants"])
    doc["metrics"] = pd.DataFrame(doc["metrics"])
    return doc
