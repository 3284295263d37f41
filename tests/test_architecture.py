"""The dependency rules of docs/architecture.md, checked on the source: no module
imports the package facade or another module's private names, and module-level
imports between the package's modules form no cycle."""

from __future__ import annotations

import ast
from pathlib import Path

import pytest

PACKAGE = Path(__file__).resolve().parents[1] / "python" / "imunoise"


def _module_name(path: Path) -> str:
    parts = path.relative_to(PACKAGE.parent).with_suffix("").parts
    return ".".join(parts[:-1] if parts[-1] == "__init__" else parts)


MODULES = {_module_name(p): p for p in PACKAGE.rglob("*.py")}


def _imports(path: Path, *, top_level_only: bool):
    """(imported module, names) pairs of a file; names empty for ``import x``."""
    tree = ast.parse(path.read_text(), filename=str(path))
    nodes = tree.body if top_level_only else list(ast.walk(tree))
    package = _module_name(path) if path.name == "__init__.py" else _module_name(path).rpartition(
        ".")[0]
    for node in nodes:
        if isinstance(node, ast.Import):
            for alias in node.names:
                yield alias.name, ()
        elif isinstance(node, ast.ImportFrom):
            base = node.module or ""
            if node.level:
                anchor = package.split(".")
                anchor = anchor[: len(anchor) - node.level + 1]
                base = ".".join([*anchor, base] if base else anchor)
            yield base, tuple(a.name for a in node.names)


def _resolve(module: str, names: tuple[str, ...]) -> list[str]:
    """Package modules an import statement loads (``from a import b`` may load a.b)."""
    submodules = [f"{module}.{n}" for n in names if f"{module}.{n}" in MODULES]
    only_submodules = names and len(submodules) == len(names)
    return submodules + ([module] if module in MODULES and not only_submodules else [])


@pytest.mark.parametrize("name", sorted(n for n in MODULES if n != "imunoise"))
def test_no_module_imports_the_facade_or_private_names(name):
    for module, names in _imports(MODULES[name], top_level_only=False):
        if module == "imunoise":
            facade = [n for n in names if f"imunoise.{n}" not in MODULES]
            assert not facade, f"{name} imports {facade} from the package facade"
            assert names, f"{name} does `import imunoise` (the facade)"
        if module.startswith("imunoise") and module in MODULES:
            private = [n for n in names if n.startswith("_") and f"{module}.{n}" not in MODULES
                       and n != "__version__"]
            assert not private, f"{name} imports private {private} from {module}"


def test_no_import_cycle_between_modules():
    graph = {
        name: {
            target
            for module, names in _imports(path, top_level_only=True)
            for target in _resolve(module, names)
            if target != name and target != "imunoise"
        }
        for name, path in MODULES.items()
        if name != "imunoise"
    }
    state: dict[str, int] = {}
    stack: list[str] = []

    def visit(node: str) -> None:
        state[node] = 1
        stack.append(node)
        for nxt in sorted(graph.get(node, ())):
            if state.get(nxt) == 1:
                cycle = stack[stack.index(nxt):] + [nxt]
                pytest.fail("import cycle: " + " -> ".join(cycle))
            if nxt not in state:
                visit(nxt)
        stack.pop()
        state[node] = 2

    for node in sorted(graph):
        if node not in state:
            visit(node)


#: What the plumbing package may import at module level: itself and what lies below it
#: (stream reads a log through readers.log; it calls scale, allan, stats inside functions).
_SUPPORT_BELOW = ("imunoise._support", "imunoise._core", "imunoise.errors", "imunoise.display",
                  "imunoise.readers")


@pytest.mark.parametrize("name", sorted(n for n in MODULES if n.startswith("imunoise._support.")))
def test_support_imports_nothing_above_it(name):
    for module, names in _imports(MODULES[name], top_level_only=True):
        for target in _resolve(module, names) if module.startswith("imunoise") else ():
            assert target.startswith(_SUPPORT_BELOW), f"{name} imports {target}"


def test_compute_modules_load_no_presentation():
    """plot and report (matplotlib) load on use: no other module imports them at its top."""
    presentation = ("imunoise.plot", "imunoise.report", "imunoise.cli")
    for name, path in MODULES.items():
        if name == "imunoise" or name.startswith(presentation):
            continue
        for module, names in _imports(path, top_level_only=True):
            for target in _resolve(module, names):
                assert not target.startswith(presentation[:2]), f"{name} imports {target}"


RUST = Path(__file__).resolve().parents[1] / "rust"


def _rust_module(path: Path) -> str:
    parts = list(path.relative_to(RUST).with_suffix("").parts)
    if parts[-1] in ("mod", "lib"):
        parts = parts[:-1]
    return "::".join(["crate", *parts])


def _rust_uses(path: Path, modules: set[str]) -> set[str]:
    """Modules of the crate a file's non-test code names (`use` paths and
    `crate::`/`super::` paths), resolved to the longest existing module."""
    import re

    own = _rust_module(path)
    source = re.split(r"#\[cfg\(test\)\]", path.read_text())[0]
    parent = own.split("::") if path.name in ("mod.rs", "lib.rs") else own.split("::")[:-1]
    found = set()
    for ref in re.findall(r"\b((?:crate|super|self)(?:::\w+)+)", source):
        segments = ref.split("::")
        if segments[0] == "crate":
            resolved = segments
        else:
            base = parent[:]
            while segments and segments[0] == "super":
                base, segments = base[:-1], segments[1:]
            if segments and segments[0] == "self":
                segments = segments[1:]
            resolved = base + segments
        for k in range(len(resolved), 0, -1):
            candidate = "::".join(resolved[:k])
            if candidate in modules:
                if candidate != own:
                    found.add(candidate)
                break
    return found


def test_no_use_cycle_between_rust_modules():
    files = [p for p in RUST.rglob("*.rs") if p.name not in ("tests.rs", "test_signals.rs")]
    modules = {_rust_module(p) for p in RUST.rglob("*.rs")}
    uses = {_rust_module(p): _rust_uses(p, modules) for p in files}
    related = [
        (a, b)
        for a, targets in uses.items()
        for b in targets
        if a in uses.get(b, ()) and not (a.startswith(b + "::") or b.startswith(a + "::"))
    ]
    assert not related, f"Rust modules that use each other: {sorted(set(related))}"


#: Modules that may write a file other than through imunoise._support.atomic, and why.
_OWN_WRITES = {
    "imunoise._support.atomic": "the helper itself",
    "imunoise.scale.convert": "appends to its staging files, themselves _atomic temporaries",
    "imunoise.readers.rosbag_reader": "bytes given as a bag go to a scratch TemporaryDirectory",
    "imunoise.recording.writer": "a recording is an append stream fsync-ed every second: it must "
                              "survive kill -9 with at most 1 s lost (its metadata is atomic)",
}
_WRITERS = {"write_text", "write_bytes", "savefig", "savetxt", "save", "savez",
            "savez_compressed", "to_csv", "to_parquet", "replace", "rename", "mkstemp"}


def _handles(tree) -> set[str]:
    """Names bound by ``with _atomic.replacing(...) as name``: writing into them is fine."""
    names = set()
    for node in ast.walk(tree):
        if isinstance(node, ast.With):
            for item in node.items:
                call = item.context_expr
                if (isinstance(call, ast.Call) and isinstance(call.func, ast.Attribute)
                        and call.func.attr == "replacing"
                        and isinstance(item.optional_vars, ast.Name)):
                    names.add(item.optional_vars.id)
    return names


@pytest.mark.parametrize("name", sorted(n for n in MODULES if n not in _OWN_WRITES))
def test_every_write_goes_through_the_atomic_helper(name):
    tree = ast.parse(MODULES[name].read_text())
    handles = _handles(tree)
    for node in ast.walk(tree):
        if not isinstance(node, ast.Call):
            continue
        func = node.func
        if isinstance(func, ast.Name) and func.id == "open" and len(node.args) > 1:
            mode = node.args[1]
            assert not (isinstance(mode, ast.Constant) and set(str(mode.value)) & set("wax+")), \
                f"{name}:{node.lineno} opens a file for writing; use imunoise._support.atomic"
        if not isinstance(func, ast.Attribute) or func.attr not in _WRITERS:
            continue
        owner = func.value
        if isinstance(owner, ast.Name) and owner.id in ("_atomic", "plot"):
            continue  # plot.save writes through _atomic
        into_handle = node.args and isinstance(node.args[0], ast.Name) \
            and node.args[0].id in handles
        if func.attr in ("replace", "rename") and not (isinstance(owner, ast.Name)
                                                       and owner.id == "os"):
            continue  # str.replace, dataclasses.replace ...
        assert into_handle, (f"{name}:{node.lineno} writes with .{func.attr}() outside "
                             "imunoise._support.atomic")
