"""The public docstrings are complete and their examples run (issue 26 §4, "Docstrings").

Every public callable (the names of ``crowdvib.__all__`` and of the public subpackages'
``__all__``, and the public methods of the public classes) documents each parameter of its
signature and no parameter it does not take, and opens with a one-sentence summary ending in a
period that autosummary's first-". " rule does not cut (issue 27 §1: "(paper Eq. 5 and 6)" came
out as "(paper Eq."). The docstrings are parsed with numpydoc's own parser (the docs render them
with numpydoc). Every ``>>>`` example in the package's docstrings runs, as ``doctest`` runs it.
"""

import dataclasses
import doctest
import importlib
import inspect
import re
from pathlib import Path

import pytest
from numpydoc import docscrape

SRC = Path(__file__).resolve().parents[2] / "src"

#: The modules whose ``__all__`` is the public API (crowdvib.reporting re-exports its figures
#: through ``reporting.plotting``; the CLI has no Python API).
PUBLIC = ("crowdvib", "crowdvib.models", "crowdvib.signals", "crowdvib.io", "crowdvib.response",
          "crowdvib.runner", "crowdvib.identification", "crowdvib.studies", "crowdvib.oma",
          "crowdvib.design", "crowdvib.comfort", "crowdvib.cases", "crowdvib.runs",
          "crowdvib.reporting.plotting")

#: autosummary's end of a summary sentence (sphinx.ext.autosummary.periods_re): a period and
#: white space. The docs relax it after "Eq."/"Fig.", but help(), IDEs and numpydoc do not.
SENTENCE_END = re.compile(r"\.\s")


def _public_callables():
    """{qualified name: object}, each callable once (many are re-exported at several levels)."""
    found = {}
    for module_name in PUBLIC:
        module = importlib.import_module(module_name)
        for name in module.__all__:
            value = getattr(module, name)
            if not callable(value) or (inspect.isclass(value)
                                       and issubclass(value, BaseException)):
                continue    # constants, and the errors (documented by their classes' text)
            found.setdefault(f"{value.__module__}.{value.__qualname__}", value)
            if inspect.isclass(value):
                for member, raw in vars(value).items():
                    function = getattr(raw, "__func__", raw)
                    if not member.startswith("_") and inspect.isfunction(function):
                        found.setdefault(f"{value.__module__}.{function.__qualname__}", raw)
    return found


CALLABLES = _public_callables()


def _names(section):
    """The names of a Parameters/Attributes section ("a, b : float" names two; "**options" one)."""
    return {part.strip().lstrip("*") for entry in section for part in entry.name.split(",")
            if part.strip()}


def _parameters(obj):
    """The parameters a caller passes (``self``/``cls`` of a method left out), or None."""
    function = getattr(obj, "__func__", obj)
    try:
        signature = inspect.signature(function)
    except (TypeError, ValueError):
        return None
    names = list(signature.parameters)
    if not inspect.isclass(function) and not isinstance(obj, staticmethod) and "." in (
            function.__qualname__) and names and names[0] in ("self", "cls"):
        names = names[1:]
    return set(names)


def _field_docs(cls):
    """Attributes of the dataclasses and named tuples in ``cls``'s crowdvib bases: their fields
    are the constructor's parameters, documented once under Attributes."""
    names = set()
    for base in cls.__mro__:
        if base.__module__.startswith("crowdvib") and (dataclasses.is_dataclass(base)
                                                       or hasattr(base, "_fields")):
            parsed = docscrape.NumpyDocString(inspect.getdoc(base) or "")
            names |= _names(parsed["Attributes"]) | _names(parsed["Parameters"])
    return names


def docstring_problems(obj):
    """What is wrong with ``obj``'s docstring (an empty list when nothing is)."""
    function = getattr(obj, "__func__", obj)
    parsed = docscrape.NumpyDocString(inspect.getdoc(function) or "")
    problems = []
    summary = " ".join(parsed["Summary"]).strip()
    if not summary.endswith("."):
        problems.append(f"the summary must be a sentence ending with a period: {summary!r}")
    elif SENTENCE_END.search(summary):
        problems.append(f"the summary holds a '. ' where autosummary cuts it: {summary!r}")
    if inspect.isclass(function) and getattr(function, "_is_protocol", False):
        return problems     # a protocol's signature is typing's, not a constructor's
    parameters = _parameters(obj)
    if parameters is None:
        return problems
    documented = _names(parsed["Parameters"]) | _names(parsed["Other Parameters"])
    accepted = documented | (_field_docs(function) if inspect.isclass(function) else set())
    if parameters - accepted:
        problems.append(f"parameters not documented: {sorted(parameters - accepted)}")
    if documented - parameters:
        problems.append(f"documented parameters it does not take: {sorted(documented - parameters)}")
    return problems


def test_the_checker_finds_what_it_should():
    # The rules themselves, on docstrings made to break them one at a time (issue 26 §4).
    def good(a, *, b=1, **options):
        """Do a thing.

        Parameters
        ----------
        a, b : float
            Two numbers.
        **options
            Passed on.
        """

    def cut(a):
        """Do a thing (paper Eq. 5).

        Parameters
        ----------
        a : float
        """

    def missing(a, b):
        """Do a thing.

        Parameters
        ----------
        a : float
        c : float
        """

    assert docstring_problems(good) == []
    assert docstring_problems(cut) == ["the summary holds a '. ' where autosummary cuts it: "
                                       "'Do a thing (paper Eq. 5).'"]
    assert docstring_problems(missing) == ["parameters not documented: ['b']",
                                           "documented parameters it does not take: ['c']"]


def test_every_public_callable_documents_its_parameters_and_summary():
    # issue 26 §4: "document every parameter ... a numpydoc validation test keeps it so". The API
    # has well over a hundred public callables and as many public methods; all must pass.
    assert len(CALLABLES) > 250
    failing = {name: problems for name, value in sorted(CALLABLES.items())
               if (problems := docstring_problems(value))}
    assert not failing, "\n".join(f"{name}: {'; '.join(problems)}"
                                  for name, problems in failing.items())


#: The public functions a reader comes to first: each cites its sources (the paper's equations,
#: Živanović 2007, Den Hartog, Welch 1967, ... as docs/theory/references.rst cites them) and
#: points to its neighbours (issue 26 §4: "add References and See Also to the public functions").
CITING = ("crowdvib.estimate_hsi", "crowdvib.estimate_hsi_joint", "crowdvib.response_psd",
          "crowdvib.frf", "crowdvib.effective_modal_properties", "crowdvib.simulate",
          "crowdvib.simulate_psd", "crowdvib.welch_psd", "crowdvib.signals.psd_convergence",
          "crowdvib.studies.objective_map", "crowdvib.studies.modelling_error_study",
          "crowdvib.studies.parametric_study", "crowdvib.design_check", "crowdvib.tune_damper",
          "crowdvib.design.optimal_tuning", "crowdvib.predict_response", "crowdvib.identify_modes",
          "crowdvib.models.weidmann_speed", "crowdvib.models.bruno_venuti_step_frequency",
          "crowdvib.ZivanovicForce", "crowdvib.YoungForce", "crowdvib.MeasuredForce",
          "crowdvib.MSDModel", "crowdvib.weight_wb", "crowdvib.running_rms")
#: Those whose See Also is enough (a neighbour holds the sources).
NEIGHBOURS = ("crowdvib.estimate_step_frequencies", "crowdvib.simulate_many",
              "crowdvib.studies.monte_carlo", "crowdvib.studies.record_length_study",
              "crowdvib.ModalModel", "crowdvib.Crowd", "crowdvib.HSIEstimate")
#: The objects a reader needs an example of first (issue 26 §4, the brief's list).
EXAMPLES = ("crowdvib.ModalModel", "crowdvib.Crowd", "crowdvib.response_psd", "crowdvib.welch_psd",
            "crowdvib.estimate_hsi", "crowdvib.simulate", "crowdvib.design_check",
            "crowdvib.tune_damper", "crowdvib.identify_modes")


def _resolve(dotted):
    module, _, name = dotted.rpartition(".")
    return getattr(importlib.import_module(module), name)


@pytest.mark.parametrize("name", CITING + NEIGHBOURS + EXAMPLES)
def test_the_main_functions_cite_their_sources_point_to_neighbours_and_show_an_example(name):
    parsed = docscrape.NumpyDocString(inspect.getdoc(_resolve(name)))
    assert parsed["See Also"] or name not in CITING + NEIGHBOURS, f"{name}: no See Also"
    assert parsed["References"] or name not in CITING, f"{name}: no References"
    assert any(line.startswith(">>>") for line in parsed["Examples"]) or name not in EXAMPLES, (
        f"{name}: no example")


def _library_modules():
    """Every module of the library (the CLI is argument parsing, with no examples to run)."""
    names = []
    for path in sorted((SRC / "crowdvib").rglob("*.py")):
        parts = list(path.relative_to(SRC).with_suffix("").parts)
        if parts[-1] == "__init__":
            parts.pop()
        if parts[1:2] not in (["cli"], ["__main__"]):
            names.append(".".join(parts))
    return names


@pytest.mark.parametrize("module_name", _library_modules())
def test_docstring_examples_run(module_name):
    # issue 26 §4: "run the examples (>>>) in CI". Each example runs in its module's namespace,
    # as ``python -m doctest`` would; a module without examples passes trivially.
    module = importlib.import_module(module_name)
    runner = doctest.DocTestRunner(optionflags=doctest.NORMALIZE_WHITESPACE | doctest.ELLIPSIS)
    report = []
    for test in doctest.DocTestFinder().find(module, module_name):
        runner.run(test, out=report.append)
    assert runner.failures == 0, "".join(report)
