#!/usr/bin/python3
"""Runs every ```bash block of a guide page (docs/guide/*.md), in order, as one bash script, the
way a reader would type them from the repository's root, and checks the files the page promises.

    run_guide.py PAGE.md --repo REPO --binary GRAVSWEEP [--workdir DIR]

The blocks run in a fresh working folder that holds links to the repository's examples/, data/,
schemas/, python/ and deploy/ and build/scheduler/gravsweep -> BINARY, so that `runs/...` is the
folder's own. Only blocks fenced exactly ```bash run (```sh blocks are shown, never run). A line
`<!-- guide-expect: PATH -->` in the page names a file that must exist (non-empty) afterwards.
Exit 0: every command succeeded and every promised file exists; 1 otherwise, naming the block.
"""
import argparse
import os
import re
import shutil
import subprocess
import sys
import tempfile
from pathlib import Path

FENCE = re.compile(r"^```(\S*)\s*$")
EXPECT = re.compile(r"<!--\s*guide-expect:\s*(\S+)\s*-->")


def blocks(page: Path):
    """(first line number, text) of each ```bash block."""
    out, lang, start, buf = [], None, 0, []
    for n, line in enumerate(page.read_text().splitlines(), 1):
        m = FENCE.match(line)
        if m and lang is None:
            lang, start, buf = m.group(1), n + 1, []
        elif line.strip() == "```" and lang is not None:
            if lang == "bash":
                out.append((start, "\n".join(buf)))
            lang = None
        elif lang is not None:
            buf.append(line)
    if lang is not None:
        sys.exit(f"{page}:{start - 1}: a code block is never closed")
    return out


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("page", type=Path)
    ap.add_argument("--repo", type=Path, required=True)
    ap.add_argument("--binary", type=Path, required=True)
    ap.add_argument("--workdir", type=Path)
    a = ap.parse_args()
    page = a.page.resolve()
    work = a.workdir or Path(tempfile.mkdtemp(prefix="guide-"))
    if (work / ".guide-run").exists():  # an earlier run's folder: start afresh
        shutil.rmtree(work)
    work.mkdir(parents=True, exist_ok=True)
    (work / ".guide-run").touch()
    for d in ("examples", "data", "schemas", "python", "deploy"):
        if not (work / d).exists():
            (work / d).symlink_to(a.repo.resolve() / d)
    (work / "build" / "scheduler").mkdir(parents=True, exist_ok=True)
    link = work / "build" / "scheduler" / "gravsweep"
    if not link.exists():
        link.symlink_to(a.binary.resolve())
    env = dict(os.environ, PYTHONPATH=str(a.repo.resolve() / "python"), GRAVSWEEP_BIN=str(a.binary.resolve()))
    env["PATH"] = "/usr/bin:/bin:" + env.get("PATH", "")  # Debian's python3 first
    found = blocks(page)
    if not found:
        print(f"{page}: no ```bash block", file=sys.stderr)
        return 1
    # One script, as one reader's shell session: variables set in a block hold in the next ones.
    script = ["set -euo pipefail", "GUIDE_BLOCK=0",
              f"trap 'echo \"{page}:$GUIDE_BLOCK: the block starting here failed\" >&2' ERR"]
    for start, text in found:
        script += [f"GUIDE_BLOCK={start}", f"echo '--- {page.name}:{start}'", text]
    p = subprocess.run(["bash", "-c", "\n".join(script)], cwd=work, env=env)
    if p.returncode != 0:
        print(f"{page}: exit {p.returncode}; working folder {work}", file=sys.stderr)
        return 1
    missing = [m for m in EXPECT.findall(page.read_text()) if not (work / m).is_file() or (work / m).stat().st_size == 0]
    if missing:
        print(f"{page}: promised files missing or empty in {work}: {', '.join(missing)}", file=sys.stderr)
        return 1
    print(f"{page.name}: {len(found)} blocks ran, every promised file is there ({work})")
    return 0


if __name__ == "__main__":
    sys.exit(main())
