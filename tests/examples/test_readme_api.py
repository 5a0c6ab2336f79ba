"""The Python examples of the README run as written (the solid one shortened to 5 ms of simulated
time)."""
import re
from pathlib import Path

README = Path(__file__).resolve().parents[2] / "README.md"


def _blocks():
    return re.findall(r"```python\n(.*?)```", README.read_text(), re.S)


def test_readme_python_example_runs(tmp_path, monkeypatch):
    block = next(b for b in _blocks() if "rr.Simulation(" in b)
    assert "end_time=1.0" in block and 'output_directory="out"' in block
    code = block.replace("end_time=1.0", "end_time=0.005").replace(
        'output_directory="out"', 'output_directory=OUT, progress=False')
    namespace = {"OUT": str(tmp_path / "out")}
    exec(compile(code, str(README), "exec"), namespace)
    summary = namespace["summary"]
    assert summary.bodies == 2 and summary.steps > 0
    assert (tmp_path / "out" / "bodies.pvd").exists()


def test_readme_fluid_example_runs(tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    block = next(b for b in _blocks() if "FluidSolver(" in b)
    namespace = {}
    exec(compile(block, str(README), "exec"), namespace)
    report = namespace["report"]
    assert report.time_step > 0 and abs(report.water_volume_error) < 1e-10
    assert namespace["fluid"].solid.any()


def test_readme_coupled_example_runs(tmp_path, monkeypatch):
    """The README's bodies-in-the-flow example, shortened to 0.02 s of simulated time."""
    monkeypatch.chdir(tmp_path)
    block = next(b for b in _blocks() if "fluid=water" in b)
    assert "end_time=0.5" in block
    code = block.replace("end_time=0.5", "end_time=0.02").replace(
        'output_directory="tank"', 'output_directory="tank", progress=False')
    namespace = {}
    exec(compile(code, str(README), "exec"), namespace)
    summary = namespace["summary"]
    assert summary.model == "coupled" and summary.bodies == 1 and summary.steps > 0
    assert (tmp_path / "tank" / "run.pvd").is_file() and (tmp_path / "tank" / "body_forces.csv").is_file()
