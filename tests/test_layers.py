"""The import-layer contract of the package (ARCHITECTURE.md, "Layers").

Every module of ``python/grainlab`` belongs to one layer; a module may import
(at module level or inside a function) only modules of its own layer or of a
layer below. io, besides, imports no analysis or plotting: it reads and
writes, and computes nothing. The test walks the syntax tree of every module,
so a lazy import inside a function counts too. No two files, and no two of
the package's subpackages, import each other, directly or round a circle
(:func:`import_cycles`). It is run by ``make lint``.
"""

from __future__ import annotations

import ast
from pathlib import Path

import pytest

PACKAGE = Path(__file__).resolve().parents[1] / "python" / "grainlab"

#: Layers, lowest first: module prefix -> layer. A module takes the layer of its
#: longest listed prefix; a module with no listed prefix is an error (give it one).
LAYERS: dict[str, int] = {
    # 0: the compiled engine and leaf helpers that import no other grainlab module
    "grainlab._core": 0,
    "grainlab._cores": 0,
    "grainlab._interrupt": 0,
    "grainlab._kernels": 0,
    "grainlab._mapping": 0,
    "grainlab._notebook": 0,
    "grainlab._progress": 0,
    "grainlab._repr": 0,
    "grainlab._child": 0,
    "grainlab._html": 0,
    "grainlab.columns": 0,
    "grainlab.paper": 0,
    "grainlab.citation": 0,  # the citation: the version (_core) and the article
    # 1: the engine API and the snapshot data model
    "grainlab": 1,
    "grainlab.bodies": 1,
    "grainlab.cement": 1,
    "grainlab.shapes": 1,
    "grainlab.simulation": 1,
    "grainlab.snapshot": 1,
    # 2: measures on snapshots and arrays (pure), and drawing
    "grainlab.analysis": 2,
    "grainlab.plot": 2,
    # 3: files
    "grainlab.io": 3,
    # 4: finished runs' files measured and drawn (reads io, computes with analysis, draws with plot)
    "grainlab.postprocess": 4,
    # 5: making samples and running tests (a run's last phase draws its figures with postprocess)
    "grainlab.samples": 5,
    "grainlab.protocols": 5,
    "grainlab.demo": 5,
    # 6: what is done with runs: reports, the reproduction, campaigns, the viewer
    "grainlab.report": 6,
    "grainlab.reproduction": 6,
    "grainlab.study": 6,
    "grainlab.viewer": 6,
    # 7: the command line
    "grainlab.commands": 7,
    "grainlab.cli": 7,
    "grainlab.__main__": 7,
}

LAYER_NAMES = ("core", "model", "analysis", "io", "post-processing", "protocols", "runs' uses", "command line")

#: (importer prefix, imported prefix) pairs forbidden although the layers allow them.
FORBIDDEN: tuple[tuple[str, str], ...] = (
    ("grainlab.io", "grainlab.analysis"),
    ("grainlab.io", "grainlab.plot"),
)

#: Known exceptions, each (importer, imported module): none today; an entry
#: needs a comment saying why and when it goes.
EXCEPTIONS: frozenset[tuple[str, str]] = frozenset()


def module_name(root: Path, path: Path) -> str:
    """``grainlab.x.y`` of a file under ``root`` (the folder holding the package)."""
    parts = list(path.relative_to(root).with_suffix("").parts)
    if parts[-1] == "__init__":
        parts.pop()
    return ".".join(parts)


def layer_of(module: str) -> tuple[int, str] | None:
    """(layer, matched prefix) of a grainlab module; None when no prefix matches."""
    parts = module.split(".")
    for k in range(len(parts), 1, -1):
        prefix = ".".join(parts[:k])
        if prefix in LAYERS:
            return LAYERS[prefix], prefix
    return (LAYERS[module], module) if module == "grainlab" else None


def _under(module: str, prefix: str) -> bool:
    return module == prefix or module.startswith(prefix + ".")


def imported_modules(tree: ast.AST, module: str, is_package: bool) -> list[tuple[int, str]]:
    """(line, module) of every grainlab import in ``tree``, wherever it stands.

    ``from grainlab import x`` counts as importing ``grainlab.x`` when ``x`` is
    a submodule name in :data:`LAYERS` terms (else the package itself);
    relative imports are resolved against ``module``.
    """
    package = module if is_package else module.rpartition(".")[0]
    found: list[tuple[int, str]] = []
    for node in ast.walk(tree):
        if isinstance(node, ast.Import):
            found += [(node.lineno, alias.name) for alias in node.names]
        elif isinstance(node, ast.ImportFrom):
            if node.level:
                base = package.split(".")[: len(package.split(".")) - node.level + 1]
                source = ".".join(base + ([node.module] if node.module else []))
            else:
                source = node.module or ""
            for alias in node.names:
                candidate = f"{source}.{alias.name}"
                hit = layer_of(candidate)
                found.append((node.lineno, candidate if hit and hit[1] == candidate else source))
    return [(line, name) for line, name in found if _under(name, "grainlab")]


def layer_violations(root: Path) -> tuple[list[str], set[tuple[str, str]]]:
    """Every import in the package under ``root`` against the layer rule, as
    ``module:line imports target (why)`` (modules without a layer are listed
    too), and the :data:`EXCEPTIONS` that were met."""
    problems: list[str] = []
    met: set[tuple[str, str]] = set()
    for path in sorted((root / "grainlab").rglob("*.py")):
        module = module_name(root, path)
        mine = layer_of(module)
        if mine is None:
            problems.append(f"{module}: no layer (add its prefix to LAYERS and ARCHITECTURE.md)")
            continue
        tree = ast.parse(path.read_text(encoding="utf-8"), filename=str(path))
        for line, target in imported_modules(tree, module, path.name == "__init__.py"):
            theirs = layer_of(target)
            if theirs is None:
                continue  # a module without a layer is reported as such
            if (module, target) in EXCEPTIONS:
                met.add((module, target))
                continue
            if theirs[0] > mine[0]:
                problems.append(
                    f"{module}:{line} imports {target}: layer {LAYER_NAMES[theirs[0]]} is above "
                    f"{LAYER_NAMES[mine[0]]}"
                )
            for low, high in FORBIDDEN:
                if _under(module, low) and _under(target, high):
                    problems.append(f"{module}:{line} imports {target}: {low} imports no {high}")
    return problems, met


def test_every_import_follows_the_layer_rule():
    problems, met = layer_violations(PACKAGE.parent)
    assert problems == []
    assert met == EXCEPTIONS, "an exception no longer needed: remove it from EXCEPTIONS"


def import_graph(root: Path) -> dict[str, set[str]]:
    """Module -> the grainlab modules it imports (at module level or lazily), each
    import resolved to the module file it reaches (``from grainlab.x import name``
    reaches ``grainlab.x``); the compiled engine counts as a module."""
    files = {module_name(root, path): path for path in sorted((root / "grainlab").rglob("*.py"))}
    known = set(files) | {m for m in LAYERS if (root / m.replace(".", "/")).with_suffix(".pyi").exists()}

    def reached(target: str) -> str:
        while target not in known and "." in target:
            target = target.rpartition(".")[0]
        return target

    graph: dict[str, set[str]] = {}
    for module, path in files.items():
        tree = ast.parse(path.read_text(encoding="utf-8"), filename=str(path))
        package = module if path.name == "__init__.py" else module.rpartition(".")[0]
        targets: set[str] = set()
        for node in ast.walk(tree):
            if isinstance(node, ast.Import):
                targets |= {reached(alias.name) for alias in node.names}
            elif isinstance(node, ast.ImportFrom):
                if node.level:
                    base = package.split(".")[: len(package.split(".")) - node.level + 1]
                    source = ".".join(base + ([node.module] if node.module else []))
                else:
                    source = node.module or ""
                targets |= {reached(f"{source}.{alias.name}") for alias in node.names}
        graph[module] = {t for t in targets if _under(t, "grainlab")} - {module}
    return graph


def _cycles(graph: dict[str, set[str]]) -> list[list[str]]:
    """The strongly connected components of more than one node (Tarjan), each sorted."""
    index: dict[str, int] = {}
    low: dict[str, int] = {}
    stack: list[str] = []
    on_stack: set[str] = set()
    found: list[list[str]] = []

    def visit(node: str) -> None:
        index[node] = low[node] = len(index)
        stack.append(node)
        on_stack.add(node)
        for other in sorted(graph.get(node, ())):
            if other not in index:
                visit(other)
                low[node] = min(low[node], low[other])
            elif other in on_stack:
                low[node] = min(low[node], index[other])
        if low[node] == index[node]:
            component = []
            while True:
                member = stack.pop()
                on_stack.discard(member)
                component.append(member)
                if member == node:
                    break
            if len(component) > 1:
                found.append(sorted(component))

    for node in sorted(graph):
        if node not in index:
            visit(node)
    return sorted(found)


def _subpackage(module: str) -> str:
    """``grainlab.x`` of ``grainlab.x.y.z`` (the package itself for ``grainlab``)."""
    return ".".join(module.split(".")[:2])


def import_cycles(root: Path) -> tuple[list[list[str]], list[list[str]]]:
    """The import circles of the package under ``root``: between files, and between
    its subpackages (``grainlab.report`` and ``grainlab.reproduction``, say)."""
    graph = import_graph(root)
    packages: dict[str, set[str]] = {}
    for module, targets in graph.items():
        mine = _subpackage(module)
        packages.setdefault(mine, set()).update(_subpackage(t) for t in targets if _subpackage(t) != mine)
    return _cycles(graph), _cycles(packages)


def test_no_import_cycle_between_files_or_packages():
    files, packages = import_cycles(PACKAGE.parent)
    assert files == [], "files that import each other (move what both need into a module of its own)"
    assert packages == [], "subpackages that import each other (one of them must not know the other)"


def test_an_import_cycle_is_caught_even_lazily(tmp_path):
    root = _synthetic_package(
        tmp_path,
        {
            "grainlab.__init__": "",
            "grainlab.report.__init__": "",
            "grainlab.report.page": "def f():\n    from grainlab.reproduction.claims import rows\n",
            "grainlab.reproduction.__init__": "",
            "grainlab.reproduction.claims": "from grainlab.report import page\n",
            "grainlab.plot.__init__": "from grainlab.plot.workers import pool\n",
            "grainlab.plot.workers": "def g():\n    from grainlab.plot import save\n",
        },
    )
    files, packages = import_cycles(root)
    assert files == [["grainlab.plot", "grainlab.plot.workers"], ["grainlab.report.page", "grainlab.reproduction.claims"]]
    assert packages == [["grainlab.report", "grainlab.reproduction"]]


def _synthetic_package(root: Path, modules: dict[str, str]) -> Path:
    for name, source in modules.items():
        path = root.joinpath(*name.split(".")).with_suffix(".py")
        path.parent.mkdir(parents=True, exist_ok=True)
        path.write_text(source, encoding="utf-8")
    return root


@pytest.mark.parametrize(
    ("source", "expected"),
    [
        ("from grainlab.io.hdf5 import read_results\n", "grainlab.analysis.bad:1 imports grainlab.io.hdf5"),
        ("def f():\n    from grainlab.report import write_report\n", "grainlab.analysis.bad:2 imports grainlab.report"),
        ("from ..protocols import config\n", "grainlab.analysis.bad:1 imports grainlab.protocols:"),
        ("import grainlab.postprocess\n", "grainlab.analysis.bad:1 imports grainlab.postprocess"),
    ],
)
def test_a_forbidden_import_in_analysis_is_caught(tmp_path, source, expected):
    root = _synthetic_package(
        tmp_path,
        {
            "grainlab.__init__": "",
            "grainlab.analysis.__init__": "",
            "grainlab.analysis.bad": source,
            "grainlab.snapshot": "",
        },
    )
    problems, _ = layer_violations(root)
    assert len(problems) == 1 and problems[0].startswith(expected), problems


def test_io_may_not_import_analysis_even_lazily(tmp_path):
    root = _synthetic_package(
        tmp_path,
        {"grainlab.io.__init__": "", "grainlab.io.vtk": "def f():\n    from grainlab.analysis import StabilityIndex\n"},
    )
    assert layer_violations(root)[0] == [
        "grainlab.io.vtk:2 imports grainlab.analysis: grainlab.io imports no grainlab.analysis"
    ]


def test_allowed_imports_and_unknown_modules(tmp_path):
    root = _synthetic_package(
        tmp_path,
        {
            "grainlab.report.ok": "from grainlab import plot\nfrom grainlab.io import results\nimport grainlab\n",
            "grainlab.analysis.ok": "from grainlab import snapshot, _core\nfrom . import fabric\n",
            "grainlab.newthing": "",
        },
    )
    assert layer_violations(root)[0] == ["grainlab.newthing: no layer (add its prefix to LAYERS and ARCHITECTURE.md)"]
