"""Import-layer rules of docs/architecture.md (STYLE 4.3), checked by parsing the source with ast.

- ``*/kernels/*`` modules import from riprap only ``riprap._jit``, other kernels and
  ``riprap.errors`` (the Python wrappers of the reference kernel raise named errors);
- only ``riprap/io/`` and ``riprap/cli.py`` touch files (open, savefig, meshio/np read & write),
  and ``riprap/_jit.py``, which hashes the kernel sources to stamp numba's cache;
- floors: every module imports riprap only from its own package or from a package on a lower
  floor of the list in docs/architecture.md ("Layers"), at the top of the file or inside a
  function alike; an import inside a function marked ``# lazy: <why>`` (start-up time) is the
  one exception, and no other riprap import hides in a function.
"""
import ast
import re
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


# Files outside io/ that may touch files, each with its reason.
FILE_TOUCHING_EXEMPTIONS = {
    # hashes riprap's own kernel sources to stamp numba's on-disk cache; it stands on the ground
    # floor, below io/, since every kernel module imports it
    "_jit.py",
}


def test_only_io_and_cli_touch_files():
    offenders = []
    for path in _modules():
        relative = path.relative_to(SOURCE)
        if (relative.parts[0] == "io" or relative.name == "cli.py"
                or relative.as_posix() in FILE_TOUCHING_EXEMPTIONS):
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


# ---------------------------------------------------------------------------------------------
# Floors

ARCHITECTURE = SOURCE.parents[1] / "docs" / "architecture.md"

# Known upward imports in files being rewritten by issue 36's other parts, each with who ends it.
# EMPTY THIS when those parts are merged: the rule then holds without exception.
UPWARD_ALLOWED = set()
# Files whose riprap imports inside functions are being rewritten by issue 36's other parts
# (the loop and scene, the writers, the key table, the armour unit kinds). EMPTY THIS when those
# parts are merged.
HIDDEN_ALLOWED = set()

LAZY_MARK = "# lazy:"


def _floors() -> dict[str, int]:
    """Unit name -> floor (1 = ground), from the numbered list in the Layers section."""
    text = ARCHITECTURE.read_text()
    section = text.split("\n## Layers", 1)[1].split("\n## ", 1)[0]
    floors = {}
    for line in section.splitlines():
        match = re.match(r"\s*(\d+)\.\s+(.*)", line)
        if match:
            for name in re.findall(r"`([^`]+)`", match.group(2)):
                floors[name] = int(match.group(1))
    return floors


def _unit_of_file(relative: Path) -> str:
    """The unit a file belongs to: its top-level package or module under riprap/; ``schema``
    for the key table (riprap/schema.py, formerly riprap/case/schema.py); ``riprap`` for the
    package's own ``__init__.py``."""
    if relative.stem == "schema" and relative.parts[:-1] in ((), ("case",)):
        return "schema"
    if len(relative.parts) == 1:
        return "riprap" if relative.name == "__init__.py" else relative.stem
    return relative.parts[0]


def _unit_of_module(module: str) -> str:
    parts = module.split(".")
    if parts[1:] in (["schema"], ["case", "schema"]):
        return "schema"
    return parts[1] if len(parts) > 1 else "riprap"


def _imported_modules(node, relative: Path):
    """Full riprap module names an import statement loads (``from riprap.case import schema``
    loads ``riprap.case.schema``; ``from riprap import analysis`` loads ``riprap.analysis``)."""
    if isinstance(node, ast.Import):
        return [alias.name for alias in node.names if alias.name.split(".")[0] == "riprap"]
    if node.level:
        base = ["riprap", *relative.parts[:-1]][:len(relative.parts) + 1 - node.level]
        module = ".".join(base + ([node.module] if node.module else []))
    else:
        module = node.module or ""
    if module.split(".")[0] != "riprap":
        return []
    folder = SOURCE.parent.joinpath(*module.split("."))
    submodules = [f"{module}.{alias.name}" for alias in node.names
                  if (folder / f"{alias.name}.py").is_file() or (folder / alias.name).is_dir()]
    return submodules or [module]


def _imports(path: Path):
    """(line, module, inside a function, marked lazy) of every riprap import of a file."""
    text = path.read_text()
    lines = text.splitlines()
    tree = ast.parse(text)
    in_function = set()
    for function in ast.walk(tree):
        if isinstance(function, (ast.FunctionDef, ast.AsyncFunctionDef)):
            in_function.update(id(node) for node in ast.walk(function))
    relative = path.relative_to(SOURCE)
    for node in ast.walk(tree):
        if isinstance(node, (ast.Import, ast.ImportFrom)):
            lazy = any(LAZY_MARK in line for line in lines[node.lineno - 1:node.end_lineno])
            for module in _imported_modules(node, relative):
                yield node.lineno, module, id(node) in in_function, lazy


def _allowed(relative: Path, names) -> bool:
    return any(relative.as_posix() == name or relative.parts[0] == name for name in names)


def test_architecture_doc_gives_every_package_a_floor():
    floors = _floors()
    assert floors, "docs/architecture.md: no numbered floor list in its Layers section"
    units = {_unit_of_file(path.relative_to(SOURCE)) for path in _modules()}
    assert sorted(units - set(floors)) == []


def test_no_import_runs_from_a_lower_floor_to_a_higher_one():
    """A module imports riprap only from its own package or from a lower floor; packages on one
    floor do not import each other. Names of the list with no module yet (a package an issue is
    adding) simply match nothing."""
    floors = _floors()
    offenders = []
    for path in _modules():
        relative = path.relative_to(SOURCE)
        unit = _unit_of_file(relative)
        for line, module, _, lazy in _imports(path):
            target = _unit_of_module(module)
            if target == unit or lazy or (relative.as_posix(), target) in UPWARD_ALLOWED:
                continue
            if target in floors and unit in floors and floors[target] >= floors[unit]:
                offenders.append(f"{relative}:{line} imports {module} (floor {floors[target]}) "
                                 f"from floor {floors[unit]}")
    assert offenders == []


def test_no_riprap_import_hides_in_a_function():
    """An import inside a function is either a deliberate lazy one, marked ``# lazy: <why>``, or
    belongs at the top of the file (hidden imports hid package loops before issue 36)."""
    offenders = []
    for path in _modules():
        relative = path.relative_to(SOURCE)
        if _allowed(relative, HIDDEN_ALLOWED):
            continue
        for line, module, hidden, lazy in _imports(path):
            if hidden and not lazy:
                offenders.append(f"{relative}:{line} imports {module} inside a function")
    assert offenders == []
