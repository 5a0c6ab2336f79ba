"""The loop only runs (issue 36): models sit below the loop and the scene. No model imports
``riprap.simulation`` or ``riprap.scene``, nor holds or reads the run (``.simulation``); the loop
(``riprap/simulation.py``) reads no private attribute of a model or a scene."""
import ast
from pathlib import Path

SOURCE = Path(__file__).resolve().parents[2] / "src" / "riprap"


def _riprap_imports(tree):
    for node in ast.walk(tree):
        if isinstance(node, ast.ImportFrom) and node.module and node.module.startswith("riprap"):
            yield node.module
        elif isinstance(node, ast.Import):
            yield from (alias.name for alias in node.names if alias.name.startswith("riprap"))


def test_models_import_neither_the_loop_nor_the_scene():
    offenders = []
    for path in sorted((SOURCE / "models").glob("*.py")):
        tree = ast.parse(path.read_text())
        offenders += [f"{path.name} imports {module}" for module in _riprap_imports(tree)
                      if module.startswith(("riprap.simulation", "riprap.scene"))]
        offenders += [f"{path.name}:{node.lineno} .simulation" for node in ast.walk(tree)
                      if isinstance(node, ast.Attribute) and node.attr == "simulation"]
    assert offenders == []


def test_the_loop_reads_no_private_attribute_of_another_object():
    tree = ast.parse((SOURCE / "simulation.py").read_text())
    offenders = [f"simulation.py:{node.lineno} {ast.unparse(node)}" for node in ast.walk(tree)
                 if isinstance(node, ast.Attribute) and node.attr.startswith("_")
                 and not node.attr.startswith("__")
                 and not (isinstance(node.value, ast.Name) and node.value.id in ("self", "cls"))]
    assert offenders == []
