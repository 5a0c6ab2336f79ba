"""The Python example of the README runs as written (shortened to 5 ms of simulated time)."""
import re
from pathlib import Path

README = Path(__file__).resolve().parents[2] / "README.md"


def test_readme_python_example_runs(tmp_path, monkeypatch):
    block = re.search(r"```python\n(.*?)```", README.read_text(), re.S).group(1)
    assert "end_time=1.0" in block and 'output_directory="out"' in block
    code = block.replace("end_time=1.0", "end_time=0.005").replace(
        'output_directory="out"', 'output_directory=OUT, progress=False')
    namespace = {"OUT": str(tmp_path / "out")}
    exec(compile(code, str(README), "exec"), namespace)
    summary = namespace["summary"]
    assert summary.bodies == 2 and summary.steps > 0
    assert (tmp_path / "out" / "bodies.pvd").exists()
