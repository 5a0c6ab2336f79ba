"""Import-layer rules of docs/architecture.md (STYLE 4.3), checked by parsing the source with ast.

- ``*/kernels/*`` modules import from riprap only ``riprap._jit``, other kernels and
  ``riprap.errors`` (the Python wrappers of the reference kernel raise named errors);
- only ``riprap/io/`` and ``riprap/cli.py`` touch files (open, savefig, meshio/np read & write).
"""
import ast
from pathlib import Path

SOURCE = Path(__file__).resolve().parents[2] / "src" / "riprap"
FILE_CALLS = {"open", "savefig", "write", "read", "save", "savez", "load", "write_text",
              "read_text", "write_bytes", "read_bytes"}
FILE_MODULES = {"meshio", "np", "numpy", "json", "builtins", "Path", "tomllib"}


def _modules():
    return sorted(SOURCE.rglob("*.py"))


def _riprap_imports(tree):
    for node in ast.walk(tree):
        if isinstance(node, ast.ImportFrom) and node.module and node.module.startswith("riprap"):
            yield node.module
        elif isinstance(node, ast.Import):
            for alias in node.names:
                if alias.name.startswith("riprap"):
                    yield alias.name


def test_kernels_import_only_kernels_and_jit():
    offenders = []
    for path in _modules():
        if path.parent.name != "kernels" or path.name == "__init__.py":
            continue
        for module in _riprap_imports(ast.parse(path.read_text())):
            allowed = (module in ("riprap._jit", "riprap.errors") or ".kernels" in module)
            if not allowed:
                offenders.append(f"{path.relative_to(SOURCE)} imports {module}")
    assert offenders == []


def test_only_io_and_cli_touch_files():
    offenders = []
    for path in _modules():
        relative = path.relative_to(SOURCE)
        if relative.parts[0] == "io" or relative.name == "cli.py":
            continue
        for node in ast.walk(ast.parse(path.read_text())):
            if not isinstance(node, ast.Call):
                continue
            func = node.func
            if isinstance(func, ast.Name) and func.id == "open":
                offenders.append(f"{relative}:{node.lineno} open()")
            elif (isinstance(func, ast.Attribute) and func.attr in FILE_CALLS
                  and isinstance(func.value, ast.Name) and func.value.id in FILE_MODULES):
                offenders.append(f"{relative}:{node.lineno} {func.value.id}.{func.attr}()")
    assert offenders == []


def test_architecture_doc_names_only_existing_modules():
    doc = (SOURCE.parents[1] / "docs" / "architecture.md").read_text()
    missing = []
    for token in doc.replace("`", " ").split():
        token = token.strip(".,;:()")
        if token.startswith("riprap/") and token.endswith(".py"):
            if not (SOURCE.parent / token).exists():
                missing.append(token)
    assert missing == []
