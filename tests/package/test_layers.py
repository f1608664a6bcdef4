"""The package's layers hold (issue 26 §4): no import cycle, every import goes down the layer
order, no private name or private module used across subpackages.

Every ``import`` of every module under ``src/crowdvib`` counts, the ones inside functions
included (they hide cycles, they do not remove them). Imports under ``if TYPE_CHECKING:`` are
exempt from the cycle and layer rules, as they never run: they name a type for an annotation
(``_validation``'s aliases of the ``models`` forces, a result's ``FigureAxes``) and can neither load
a module nor close a cycle; the privacy rule still applies to them.

The layer order, lowest first; a module may import its own layer and the layers before it:

1. base: ``errors``, ``_validation``, ``_plausibility``, ``_files``, ``_resources``,
   ``_version``, ``_figures``, ``quantities``, ``_estimators`` (the top-level modules every layer
   may use; their names are public to the package). ``_figures`` is what every figure shares:
   each layer draws its own results (its ``plots`` module, behind their ``plot()``),
   ``reporting.plotting`` re-exports them all
2. ``models``: the structure, the pedestrians, the crowd and their forces
3. ``signals``: records, spectra, weighting, synthesis
4. ``io``: files into the types of ``models`` and ``signals``, and nothing of the analysis (so
   ``[design]`` is checked by the design layer that uses it, not by ``io`` importing ``design``)
5. ``oma``: the empty bridge's modes from ambient records, the workflow's first step (its
   cross-check states its errors at the studies' paper levels, which live in ``_estimators``)
6. ``response``: the forward models, in two families that never import each other:
   ``response.frequency_domain`` (the spectral models) and ``response.time_domain`` (the simulator)
7. ``runner``: the studies' task runner (task files, the executor, crowdvib's worker pool)
8. ``identification``: the inverse problem, the MSD from a measured PSD
9. ``studies``: the objective landscape, the modelling-error, parametric and Monte Carlo studies
10. ``design``: the code checks and the damper design
11. ``comfort``: a year of comfort (traffic, the window's comfort measure, the year), built on
    the response, the runner's pool and the design layer's classes and dampers
12. ``_manifest``: a results directory's manifest (it reads the runner's task files; a case
    verifies another run's results.json against it before use)
13. ``cases``: what a case file describes, run from Python (the commands' pipelines: it reads
    with ``io`` and computes with the layers below it, so each command only prints and writes)
14. ``reporting``: figures and the HTML report
15. ``runs``: the commands as calls (a case's work, its figures and report in a results folder
    written safely), so each command is argument parsing, one call and printing
16. ``cli``: the command line
17. the package itself (``crowdvib/__init__``, ``__main__``): it re-exports the public API.
"""

import ast
from collections import defaultdict
from pathlib import Path

SRC = Path(__file__).resolve().parents[2] / "src"
PACKAGE = "crowdvib"

BASE = ("crowdvib.errors", "crowdvib._validation", "crowdvib._plausibility", "crowdvib._files",
        "crowdvib._resources", "crowdvib._version", "crowdvib._figures", "crowdvib.quantities",
        "crowdvib._estimators")
#: Lowest first; each entry is the set of units (subpackages or top-level modules) of one layer.
LAYERS = (BASE, ("crowdvib.models",), ("crowdvib.signals",), ("crowdvib.io",),
          ("crowdvib.oma",), ("crowdvib.response",), ("crowdvib.runner",),
          ("crowdvib.identification",), ("crowdvib.studies",), ("crowdvib.design",),
          ("crowdvib.comfort",), ("crowdvib._manifest",),
          ("crowdvib.cases",), ("crowdvib.reporting",), ("crowdvib.runs",),
          ("crowdvib.cli",),
          ("crowdvib", "crowdvib.__main__"))

def _module_name(path):
    parts = list(path.relative_to(SRC).with_suffix("").parts)
    return ".".join(parts[:-1] if parts[-1] == "__init__" else parts)


MODULES = {_module_name(path): path for path in sorted((SRC / PACKAGE).rglob("*.py"))}


def _type_checking_nodes(tree):
    """The nodes under ``if TYPE_CHECKING:`` (they never run)."""
    nodes = set()
    for node in ast.walk(tree):
        if isinstance(node, ast.If) and "TYPE_CHECKING" in ast.unparse(node.test):
            for child in node.body:
                nodes.update(ast.walk(child))
    return nodes


def _imports(name):
    """(imported module, imported name or None, line, runs) of every import in module ``name``,
    relative ones resolved; ``from package import module`` names the module."""
    path = MODULES[name]
    tree = ast.parse(path.read_text(encoding="utf-8"))
    type_only = _type_checking_nodes(tree)
    package = name.split(".") if path.name == "__init__.py" else name.split(".")[:-1]
    found = []
    for node in ast.walk(tree):
        runs = node not in type_only
        if isinstance(node, ast.Import):
            found += [(alias.name, None, node.lineno, runs) for alias in node.names]
        elif isinstance(node, ast.ImportFrom):
            base = node.module or ""
            if node.level:
                base = ".".join(package[:len(package) - node.level + 1] + [base]).strip(".")
            for alias in node.names:
                if f"{base}.{alias.name}" in MODULES:
                    found.append((f"{base}.{alias.name}", None, node.lineno, runs))
                else:
                    found.append((base, alias.name, node.lineno, runs))
    return [row for row in found if row[0] == PACKAGE or row[0].startswith(PACKAGE + ".")]


IMPORTS = {name: _imports(name) for name in MODULES}


def _unit(module):
    """The subpackage or top-level module that ``module`` belongs to."""
    return ".".join(module.split(".")[:2])


RANK = {unit: rank for rank, layer in enumerate(LAYERS) for unit in layer}


def _find_cycle(graph):
    """A cycle of ``graph`` (node → set of nodes) as a path [a, b, ..., a], or None."""
    finished = set()
    for start in sorted(graph):
        path, stack = [start], [iter(sorted(graph[start]))]
        while stack:
            child = next(stack[-1], None)
            if child is None:
                finished.add(path.pop())
                stack.pop()
            elif child in path:
                return path[path.index(child):] + [child]
            elif child not in finished:
                path.append(child)
                stack.append(iter(sorted(graph.get(child, ()))))
    return None


def _runtime_edges(imports):
    """(importer, imported module, line) of the imports that run, to modules of the package."""
    return [(name, target, line) for name, rows in imports.items()
            for target, _, line, runs in rows if runs and target in MODULES]


def _graph(imports, node):
    graph = defaultdict(set)
    for importer, target, _ in _runtime_edges(imports):
        if node(importer) != node(target):
            graph[node(importer)].add(node(target))
    return graph


def _upward(imports):
    return [f"{importer}:{line} imports {target}"
            for importer, target, line in _runtime_edges(imports)
            if RANK[_unit(target)] > RANK[_unit(importer)]]


def _private_crossings(imports):
    """Imports of a private module or name (``_x``, not ``__x__``) from another subpackage. The
    base modules are private to users and public to the package; inside them, as everywhere
    else, a leading underscore means "this subpackage (or module) only"."""
    crossing = []
    for importer, rows in imports.items():
        for target, name, line, _ in rows:
            if _unit(target) == _unit(importer):
                continue
            parts = (target.split(".")[2:] if _unit(target) not in BASE else []) + [name or ""]
            if any(part.startswith("_") and not part.startswith("__") for part in parts):
                crossing.append(f"{importer}:{line} imports {target} {name or ''}".strip())
    return crossing


def test_every_unit_has_a_layer():
    # a new subpackage or top-level module must be placed in the order (the docstring above)
    assert sorted({_unit(name) for name in MODULES} - set(RANK)) == []


def test_no_cycle_between_modules():
    assert _find_cycle(_graph(IMPORTS, lambda module: module)) is None


def test_no_cycle_between_subpackages():
    # the base modules are units of their own here: errors, _files, ... must not form a ring
    assert _find_cycle(_graph(IMPORTS, _unit)) is None


def test_imports_go_down_the_layers():
    assert _upward(IMPORTS) == []


def test_no_private_name_across_subpackages():
    assert _private_crossings(IMPORTS) == []


def test_the_two_forward_model_families_never_import_each_other():
    # issue 34 §4: response/ is cut along its seam, the spectral models
    # (response.frequency_domain) and the simulator (response.time_domain); only the package's
    # __init__ re-exports both. Every import counts here, the type-only ones too.
    families = ("crowdvib.response.frequency_domain", "crowdvib.response.time_domain")

    def family(module):
        return next((f for f in families if module == f or module.startswith(f + ".")), None)

    crossing = [f"{importer}:{line} imports {target}" for importer, rows in IMPORTS.items()
                for target, _, line, _ in rows
                if family(importer) and family(target) and family(importer) != family(target)]
    assert crossing == []
    # and the cut is real: each family holds modules (a rename cannot empty the test)
    assert all(sum(family(name) == f for name in MODULES) >= 8 for f in families)


def test_function_level_relative_and_type_only_imports_are_seen():
    # the walk reaches into functions and resolves ``..``: runs/modes.py imports the ambient
    # pipeline inside run_modes() (it brings numpy and io, crowdvib --help must not); _validation's
    # imports of the forces are under TYPE_CHECKING, so they do not run
    assert ("crowdvib.cases.ambient", "identify_ambient") in {
        (target, name) for target, name, _, runs in IMPORTS["crowdvib.runs.modes"] if runs}
    typing_rows = {(target, runs) for target, _, _, runs in IMPORTS["crowdvib._validation"]}
    assert ("crowdvib.models.loading", False) in typing_rows


def test_the_checks_catch_what_the_rules_forbid():
    # hand-made imports: signals reaching up into reporting for a private name, a cycle between
    # two modules by a function-level import, and a legal downward import
    row = {"crowdvib.signals.spectrum": [("crowdvib.reporting.plotting", "_axes", 3, True)],
           "crowdvib.io.femodes": [("crowdvib.io.modalfiles", None, 5, True)],
           "crowdvib.io.modalfiles": [("crowdvib.io.femodes", None, 9, True)],
           "crowdvib.response.results": [("crowdvib.signals.welch", "welch_psd", 7, True)]}
    assert _upward(row) == ["crowdvib.signals.spectrum:3 imports crowdvib.reporting.plotting"]
    assert _private_crossings(row) == [
        "crowdvib.signals.spectrum:3 imports crowdvib.reporting.plotting _axes"]
    assert _find_cycle(_graph(row, lambda module: module)) == [
        "crowdvib.io.femodes", "crowdvib.io.modalfiles", "crowdvib.io.femodes"]


def test_cycle_finder_reports_the_path():
    # the finder itself, on a hand-made graph: a → b → c → a, d outside it
    assert _find_cycle({"a": {"b"}, "b": {"c"}, "c": {"a"}, "d": {"a"}}) == ["a", "b", "c", "a"]
    assert _find_cycle({"a": {"b"}, "b": set()}) is None
