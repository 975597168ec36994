"""The layers of the package, read from its imports (every import statement, at module
level or inside a function): physics -> engine -> pipeline -> outputs -> wings -> cli.

Rules (issue 15):
* base modules (constants, errors, interrupts, files, complexstep, _version, data,
  shipped, numbacache, compileguard, cpus) import no other layer;
* physics and engine are independent of each other and import only base modules;
* the pipeline imports base, physics and engine; outputs import those and the pipeline;
* a wing (fit, golden, campaign, bench) imports the layers below it, never another wing
  but one: the campaign builds on uq golden's bins, KPIs and report renderer (golden
  never imports the campaign: it reads a campaign's results file, no code);
* the command line may import anything but the package face;
* nothing imports the package face ``uq/__init__`` (``import uq``, ``uq.run``, ...);
* no import cycles between modules.
"""
import ast
import subprocess
import sys
import tomllib
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
PACKAGE = ROOT / "uq"
BASE = {"uq._version", "uq.constants", "uq.errors", "uq.interrupts", "uq.files",
        "uq.complexstep", "uq.data", "uq.shipped", "uq.numbacache", "uq.compileguard",
        "uq.cpus"}
#: layer -> the layers it may import (besides itself and the base)
ALLOWED = {"base": set(), "physics": set(), "engine": set(),
           "pipeline": {"physics", "engine"},
           "outputs": {"physics", "engine", "pipeline"},
           "fit": {"physics", "engine", "pipeline", "outputs"},
           "golden": {"physics", "engine", "pipeline", "outputs"},
           "campaign": {"physics", "engine", "pipeline", "outputs", "golden"},
           "bench": {"physics", "engine", "pipeline", "outputs"},
           "cli": {"physics", "engine", "pipeline", "outputs", "fit", "golden", "campaign",
                   "bench"}}


def module_name(path):
    parts = path.relative_to(ROOT).with_suffix("").parts
    return ".".join(parts[:-1] if parts[-1] == "__init__" else parts)


def layer(module):
    """The layer of a module name ('face' for the package's __init__)."""
    if module == "uq":
        return "face"
    top = ".".join(module.split(".")[:2])
    return "base" if top in BASE else module.split(".")[1]


def imports(path, modules):
    """uq modules imported anywhere in the file at `path`."""
    name = module_name(path)
    package = name if path.name == "__init__.py" else name.rpartition(".")[0]
    found = set()
    for node in ast.walk(ast.parse(path.read_text())):
        if isinstance(node, ast.Import):
            found.update(a.name for a in node.names if a.name.split(".")[0] == "uq")
        elif isinstance(node, ast.ImportFrom):
            base = node.module or ""
            if node.level:
                anchor = package.split(".")[:len(package.split(".")) - node.level + 1]
                base = ".".join(anchor + ([base] if base else []))
            if base.split(".")[0] != "uq":
                continue
            for alias in node.names:           # `from uq.x import y`: y may be a module
                child = f"{base}.{alias.name}"
                found.add(child if child in modules else base)
    return found


def import_graph():
    files = {module_name(p): p for p in PACKAGE.rglob("*.py")}
    return {name: imports(path, set(files)) for name, path in files.items()}


def violations(graph):
    """Every import that breaks a rule, and every cycle, as text."""
    problems = []
    for module, targets in graph.items():
        for target in targets:
            source_layer, target_layer = layer(module), layer(target)
            if target_layer == "face":
                problems.append(f"{module} imports the package face ({target})")
            elif target_layer not in ({source_layer, "base"} | ALLOWED.get(source_layer, set())):
                problems.append(f"{module} ({source_layer}) imports {target} ({target_layer})")
    problems += [f"import cycle: {' -> '.join(cycle)}" for cycle in cycles(graph)]
    return problems


def cycles(graph):
    """Strongly connected components of more than one module (Tarjan), or self-imports."""
    index, low, stack, on_stack, found = {}, {}, [], set(), []

    def visit(node):
        index[node] = low[node] = len(index)
        stack.append(node)
        on_stack.add(node)
        for child in graph.get(node, ()):
            if child not in index:
                visit(child)
                low[node] = min(low[node], low[child])
            elif child in on_stack:
                low[node] = min(low[node], index[child])
        if low[node] == index[node]:
            component = []
            while True:
                member = stack.pop()
                on_stack.discard(member)
                component.append(member)
                if member == node:
                    break
            if len(component) > 1 or node in graph.get(node, ()):
                found.append(sorted(component))

    for node in list(graph):
        if node not in index:
            visit(node)
    return found


def test_the_package_keeps_its_layers():
    assert violations(import_graph()) == []


def test_the_layers_are_folders():
    graph = import_graph()
    assert {layer(m) for m in graph} == set(ALLOWED) | {"face"}
    assert len([m for m in graph if layer(m) == "base"]) <= 10    # the base stays small


@pytest.mark.parametrize("extra, expected", [
    ({"uq.physics.wind": {"uq.engine.statistics"}}, "uq.physics.wind (physics) imports "
     "uq.engine.statistics (engine)"),
    ({"uq.engine.gum": {"uq.physics.rotation"}}, "(engine) imports uq.physics.rotation"),
    ({"uq.pipeline.sweep": {"uq.outputs.figures"}}, "(pipeline) imports uq.outputs.figures"),
    ({"uq.golden.plots": {"uq.fit.plots"}}, "(golden) imports uq.fit.plots (fit)"),
    ({"uq.golden.analysis": {"uq.campaign.correction"}},
     "(golden) imports uq.campaign.correction (campaign)"),
    ({"uq.outputs.report": {"uq"}}, "imports the package face"),
    ({"uq.physics.scene": {"uq.physics.measurement"}}, "import cycle: "),
])
def test_a_back_arrow_or_a_cycle_is_caught(extra, expected):
    """The checker itself: one forbidden import added to the real graph is reported."""
    graph = import_graph()
    for module, targets in extra.items():
        graph[module] = graph[module] | targets
    assert any(expected in problem for problem in violations(graph)), violations(graph)


def test_the_packages_list_of_pyproject_is_complete():
    """pyproject.toml lists the packages explicitly (the shipped scenarios are mapped from
    the top-level folder); every package folder must be in it."""
    config = tomllib.loads((ROOT / "pyproject.toml").read_text())["tool"]["setuptools"]
    folders = {module_name(p) for p in PACKAGE.rglob("__init__.py")}
    assert set(config["packages"]) == folders | {"uq.shipped"}
    assert config["package-dir"] == {"uq.shipped": "scenarios"}


HEAVY = ("scipy", "xarray", "pandas", "matplotlib", "numba")


@pytest.mark.parametrize("statement", ["import uq", "import uq.cli; uq.cli.build_parser()",
                                       "import uq; uq.__version__; uq.__all__"])
def test_a_fast_start_imports_nothing_heavy(statement):
    code = (f"import sys; {statement}; print(sorted({{m.split('.')[0] for m in sys.modules}}"
            f" & set({HEAVY!r})))")
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                         check=True).stdout.strip()
    assert out == "[]"


def test_public_names_resolve_lazily():
    import uq
    assert callable(uq.run) and callable(uq.propagate) and callable(uq.load_scenario)
    assert uq.Input.__name__ == "Input" and uq.complexstep.hypot(3.0, 4.0) == 5.0
    assert issubclass(uq.ScenarioError, uq.InputError)
    assert set(uq.__all__) <= set(dir(uq))
    with pytest.raises(AttributeError):
        uq.no_such_name
