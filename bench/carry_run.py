"""Carry a bench's test series to another machine (or another session's fresh machine) so that
it resumes there: ``pack`` writes into one .tar.gz the files of an output folder of
``bench/damage_curve.py`` that the series needs to go on, ``unpack`` puts them back at the same
absolute path (the steps' case files name the pack by it).

What is carried: the pack (without its deposition frames), the series' record and start survey,
every step's case, summary, survey and tables; the first step's bodies at its start (frame 0 and
``body_forces.csv``, from which every later survey counts displacements); the last finished
step's checkpoint (the next step starts from it); and the whole folder of a step not finished
(its checkpoint, frames of bodies and tables, which its survey reads when it ends). Left out:
the fluid frames (``*.vti``) and free-surface pictures, and the frames, forces and checkpoints
of finished steps that nothing reads again.

    python bench/carry_run.py pack   OUT_FOLDER ARCHIVE.tar.gz
    python bench/carry_run.py unpack ARCHIVE.tar.gz [--root DIR]

``--root`` puts the files under DIR instead of / (to look at them; a resume needs them at /).
"""
import argparse
import sys
import tarfile
from pathlib import Path


def _carried(out: Path) -> list[Path]:
    series = out / "series"
    steps = sorted(p for p in series.glob("step_*") if p.is_dir())
    finished = [s for s in steps if (s / "summary.json").is_file()]
    last_finished = finished[-1] if finished else None
    first = steps[0] if steps else None
    files = []
    for path in sorted(out.rglob("*")):
        if not path.is_file():
            continue
        relative = path.relative_to(out)
        parts = relative.parts
        if path.suffix == ".vti" or "free_surface" in parts or "deposition" in parts:
            continue
        if parts[:2] == ("pack", "underlayer") and parts[-1] != "summary.json":
            continue            # the underlayer's own settling run: its frames and checkpoint
        step = series / parts[1] if len(parts) > 2 and parts[0] == "series" else None
        if step in finished and parts[2] != "survey":
            name = parts[2]
            keep = (name in ("summary.json", "step.toml", "solver_log.csv", "gauges.csv")
                    or (step == last_finished and name == "checkpoint.npz")
                    or (step == first and name in ("body_forces.csv", "bodies_000000.vtu",
                                                   "bodies.pvd")))
            if not keep:
                continue
        files.append(path)
    return files


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("action", choices=("pack", "unpack"))
    parser.add_argument("paths", nargs="+")
    parser.add_argument("--root", default="/")
    args = parser.parse_args()
    if args.action == "pack":
        if len(args.paths) != 2:
            sys.exit("carry_run.py pack OUT_FOLDER ARCHIVE.tar.gz")
        out, archive = Path(args.paths[0]).resolve(), Path(args.paths[1])
        if not (out / "series").is_dir():
            sys.exit(f"{out}: no series folder (is it an output folder of bench/damage_curve.py?)")
        files = _carried(out)
        with tarfile.open(archive, "w:gz") as tar:
            for path in files:
                tar.add(path, arcname=str(path))
        print(f"{archive}: {len(files)} files of {out}, {archive.stat().st_size / 1e6:.1f} MB")
        return
    if len(args.paths) != 1:
        sys.exit("carry_run.py unpack ARCHIVE.tar.gz")
    with tarfile.open(args.paths[0], "r:gz") as tar:
        names = tar.getnames()
        tar.extractall(args.root, filter="data")
    print(f"{len(names)} files put back under {args.root}")


if __name__ == "__main__":
    main()
