"""Report templates: a consultancy's own page (its letterhead) around the report's blocks (issue
27 §4).

A template is a Jinja2 HTML file named by the case file's ``[report] template`` (or
:func:`crowdvib.reporting.report.write_report`'s ``template``). It receives:

* the report's blocks, each finished HTML: ``header``, ``nav``, ``summary``, ``estimate``,
  ``diagnostics``, ``figures``, ``inputs``, ``provenance``, and ``body`` (all of them in order);
* ``title``, ``generator``, ``css`` (the report's own style, to keep or to extend);
* ``report``: the case's ``[report]`` table (``report.client``, ``report.project``, …; a key the
  case file left out is empty);
* ``embed(name)``: a PNG, JPEG, GIF or SVG file beside the template (a logo) as a ``data:`` URI.

Every value is escaped (autoescaping; the blocks are already markup), and a name the template
does not know is an error rather than an empty string. A template comes from someone else: it is
data, never instructions (issue 35 §1). It runs in Jinja2's sandbox with limits
(``_sandbox``): no ``{% include %}``, ``{% extends %}`` or ``{% import %}`` (a template is
one file), no huge strings or numbers, at most :data:`MAX_ITERATIONS` loop steps and
:data:`MAX_SECONDS` of rendering, a page of bounded size. The page it renders must open without a network and run nothing, as the built-in
one does: it passes an allow-list of tags, attributes, URLs and CSS
(:mod:`crowdvib.reporting.safe_html`), and crowdvib puts its Content-Security-Policy first in its
``<head>``. Jinja2 is needed only when a template is used (``pip install jinja2``).
"""

import base64
import time
from pathlib import Path

from markupsafe import Markup

from .._files import child_path
from ..errors import terminal_safe
from ..errors import CrowdvibError, DataError, ParameterError
from .safe_html import checked_page
from .sections import REPORT_FIELDS

__all__ = ["render_template", "BLOCKS"]

#: The report's blocks a template places, in the order of the built-in page.
BLOCKS = ("header", "nav", "summary", "estimate", "diagnostics", "figures", "inputs",
          "provenance")
_IMAGES = {".png": "image/png", ".jpg": "image/jpeg", ".jpeg": "image/jpeg",
           ".gif": "image/gif", ".svg": "image/svg+xml"}


def render_template(path, blocks, *, title, generator, css, report=None):
    """The report's page laid out by the template at ``path``.

    Parameters
    ----------
    path : str or pathlib.Path
        The Jinja2 template (HTML).
    blocks : dict
        Block name (:data:`BLOCKS`) → its HTML (Markup).
    title, generator : str
    css : Markup
        The report's style.
    report : dict, optional
        The case's ``[report]`` table.

    Returns
    -------
    str

    Raises
    ------
    DataError
        If the template file is missing or Jinja2 is not installed.
    ParameterError
        If the template is not valid Jinja2, uses a name it is not given, embeds a file it may
        not, brings in another file, goes past a limit of the sandbox, or its page holds what
        the allow-list refuses (:func:`crowdvib.reporting.safe_html.checked_page`); the message
        names the template.
    """
    path = Path(path)
    if not path.is_file():
        raise DataError(f"report template {path} does not exist")
    if path.stat().st_size > _MAX_TEMPLATE:
        raise ParameterError(f"report template {path.name}: holds {path.stat().st_size} bytes, "
                             f"more than a page's {_MAX_TEMPLATE}")
    try:
        from jinja2 import StrictUndefined, TemplateError
    except ImportError:
        raise DataError(f"report template {path.name}: templates need Jinja2, which is not "
                        "installed (pip install jinja2)") from None
    given = report if isinstance(report, dict) else {}
    context = {**{name: Markup(blocks.get(name, "")) for name in BLOCKS},
               "body": Markup("\n").join(Markup(blocks.get(name, "")) for name in BLOCKS),
               "title": title, "generator": generator, "css": Markup(css),
               "report": {key: str(given.get(key) or "") for key, _ in REPORT_FIELDS},
               "embed": lambda name: _embedded(path, name)}
    # What the template is given bounds what it may make: each value, and the page, a few
    # times the report's own blocks (a template may place a block twice), plus room for text.
    limit = _ROOM + 4 * sum(len(context[name]) for name in (*BLOCKS, "css"))
    environment = _sandbox(StrictUndefined, limit)
    try:
        template = environment.from_string(_checked_tree(environment, path))
        pieces, size = [], 0
        for piece in template.generate(context):
            size += len(piece)
            if size > limit:
                raise _Limit(f"its page grows past {limit} characters (a few times the "
                             "report's own blocks)")
            pieces.append(piece)
    except _Limit as error:
        raise ParameterError(f"report template {path.name}: {error}") from None
    except CrowdvibError:
        raise
    except TemplateError as error:
        line = f" (line {error.lineno})" if getattr(error, "lineno", None) else ""
        raise ParameterError(f"report template {path.name}{line}: "
                             f"{terminal_safe(error)}") from None
    except Exception as error:      # the template's own doing: 1/0, a recursion, a bad type
        raise ParameterError(f"report template {path.name}: {type(error).__name__}: "
                             f"{terminal_safe(error)}") from None
    return checked_page("".join(pieces), path.name)


#: Room a template's own text and values have, above a few times the report's blocks [chars].
_ROOM = 1 << 22
#: Largest file embed() puts into a page [bytes]: a logo, not a film.
_MAX_EMBEDDED = 1 << 22
#: Largest template file [bytes].
_MAX_TEMPLATE = 1 << 20
#: Loop steps a template may take in all: a letterhead loops over a handful of values.
MAX_ITERATIONS = 100_000
#: Seconds a template may take to render: a backstop for work no count bounds (a macro that
#: calls itself twice, a filter over the whole report in each of many loop steps).
MAX_SECONDS = 10.0
#: Largest number a template may pass to a call or a filter.
MAX_NUMBER = 100_000
_MAX_BITS = 4096
#: Filters a template may use: each makes a value no longer than a few times its input.
_FILTERS = ("abs", "capitalize", "count", "d", "default", "dictsort", "e", "escape", "first",
            "float", "int", "items", "join", "last", "length", "list", "lower", "max", "min",
            "reverse", "round", "safe", "sort", "string", "striptags", "title", "trim",
            "truncate", "unique", "upper", "wordcount")
#: Methods of a string a template may call (none that pads, repeats or formats).
_STRING_METHODS = frozenset({"upper", "lower", "title", "capitalize", "strip", "lstrip", "rstrip",
                             "startswith", "endswith", "split", "isdigit", "isalpha"})


class _Limit(ParameterError):
    """A template goes past a limit of the sandbox (the message is completed with its name)."""

    def __init__(self, message):
        super().__init__(f"{message}: a report template may not compute that much")


def _sandbox(undefined, limit):
    """A sandboxed environment whose operators, calls, filters and loops have limits."""
    from jinja2.runtime import markup_join
    from jinja2.sandbox import ImmutableSandboxedEnvironment

    class Sandbox(ImmutableSandboxedEnvironment):
        # Intercepted, these operators are also never folded into constants at compile time.
        intercepted_binops = frozenset({"*", "**", "+", "%"})

        def crowdvib_tick(self):
            if time.monotonic() > self.crowdvib_deadline:
                raise _Limit(f"it renders for more than {MAX_SECONDS:g} s")

        def call_binop(self, context, operator, left, right):
            self.crowdvib_tick()
            _check_operation(operator, left, right, limit)
            return super().call_binop(context, operator, left, right)

        def call(__self, __context, __obj, *args, **kwargs):  # noqa: N805 (jinja2's names)
            __self.crowdvib_tick()
            _check_numbers(args, kwargs)
            return super().call(__context, __obj, *args, **kwargs)

        def wrap_str_format(self, value):
            # The sandbox's own str.format would pass ("{:>1000000000}"): none at all.
            return None

        def is_safe_attribute(self, obj, attr, value):
            if isinstance(obj, str) and callable(value) and attr not in _STRING_METHODS:
                return False
            return super().is_safe_attribute(obj, attr, value)

        def crowdvib_loop(self, iterable):
            """Each loop's items, counted against the template's :data:`MAX_ITERATIONS`."""
            for item in iterable:
                self.crowdvib_tick()
                self.crowdvib_steps += 1
                if self.crowdvib_steps > MAX_ITERATIONS:
                    raise _Limit(f"its loops take more than {MAX_ITERATIONS} steps")
                yield item

        def crowdvib_concat(self, *parts):
            """``a ~ b``, its length checked first (a string doubled in a loop)."""
            self.crowdvib_tick()
            if _size(parts, limit) > limit:
                raise _Limit(f"~ makes a string of more than {limit} characters")
            return markup_join(parts)

    environment = Sandbox(autoescape=True, undefined=undefined)
    environment.crowdvib_steps = 0
    environment.crowdvib_deadline = time.monotonic() + MAX_SECONDS
    environment.filters = {name: _guarded(environment.filters[name], limit, environment)
                           for name in _FILTERS}
    del environment.globals["lipsum"]       # made-up text, as much as asked: nothing a page needs
    return environment


def _guarded(function, limit, environment):
    """A filter whose numbers are checked, and ``join``'s separator times its items."""
    from jinja2.utils import _PassArg

    def guarded(*args, **kwargs):
        environment.crowdvib_tick()
        _check_numbers(args, kwargs)
        if function.__name__.endswith("do_join"):
            first = 1 if _PassArg.from_obj(function) else 0
            items = list(args[first])
            separator = args[first + 1] if len(args) > first + 1 else kwargs.get("d", "")
            if _size(items, limit) + len(items) * len(str(separator)) > limit:
                raise _Limit(f"join makes a string of more than {limit} characters")
            args = (*args[:first], items, *args[first + 1:])
        return function(*args, **kwargs)

    if hasattr(function, "jinja_pass_arg"):
        guarded.jinja_pass_arg = function.jinja_pass_arg
    return guarded


def _check_numbers(args, kwargs):
    for value in (*args, *kwargs.values()):
        if isinstance(value, int) and not isinstance(value, bool) and abs(value) > MAX_NUMBER:
            raise _Limit(f"a call is given the number {value} (more than {MAX_NUMBER})")


def _check_operation(operator, left, right, limit):
    """Refuse ``left operator right`` if its result would be huge (before it is computed)."""
    numbers = all(isinstance(v, (int, float)) for v in (left, right))
    if operator == "%" and isinstance(left, str):
        raise _Limit("% formats a string (its width is unbounded); join with ~ instead")
    if operator == "*" and not numbers:
        count = right if isinstance(right, int) else left if isinstance(left, int) else 1
        sequence = left if not isinstance(left, (int, float)) else right
        if _size(sequence, limit) * max(count, 0) > limit:
            raise _Limit(f"* makes a value of {_size(sequence, limit)} × {count} characters "
                         f"(more than {limit})")
    elif operator == "+" and not numbers:
        if _size(left, limit) + _size(right, limit) > limit:
            raise _Limit(f"+ makes a value of more than {limit} characters")
    elif all(isinstance(v, int) for v in (left, right)) and operator in ("*", "**"):
        bits = (left.bit_length() + right.bit_length() if operator == "*"
                else left.bit_length() * right if right > 0 and abs(left) > 1 else 0)
        if bits > _MAX_BITS:
            raise _Limit(f"{left} {operator} {right} is a number of about {bits} bits (more "
                         f"than {_MAX_BITS})")


def _size(value, limit):
    """About the characters ``str(value)`` has (strings, and lists, tuples and dicts of them:
    ``[body] * 100000`` is small as a list, huge as text), counted up to ``limit`` + 1."""
    total, stack = 0, [value]
    while stack and total <= limit:
        item = stack.pop()
        if isinstance(item, str):
            total += len(item)
        elif isinstance(item, (list, tuple, dict)):
            total += 2 + 2 * len(item)              # brackets and separators
            stack.extend(item.items() if isinstance(item, dict) else item)
        else:
            total += 8
    return total


#: Tags that would bring in another file, or turn autoescaping off, with the rule.
_REFUSED_TAGS = {"Include": "{% include %}", "Extends": "{% extends %}",
                 "Import": "{% import %}", "FromImport": "{% from … import %}",
                 "EvalContextModifier": "{% autoescape %}",
                 "ScopedEvalContextModifier": "{% autoescape %}"}


def _checked_tree(environment, path):
    """The template's syntax tree, refused if it brings in other files, and with every loop
    counted and every ``~`` checked (through the environment's guards)."""
    from jinja2 import nodes
    from jinja2.visitor import NodeTransformer

    tree = environment.parse(path.read_text(encoding="utf-8"), name=path.name)
    for node in tree.find_all(tuple(getattr(nodes, name) for name in _REFUSED_TAGS)):
        raise ParameterError(
            f"report template {path.name} (line {node.lineno}): holds "
            f"{_REFUSED_TAGS[type(node).__name__]}: a report template is one file of its own "
            "(no other template, no autoescaping turned off); copy what it needs into it")
    for node in tree.find_all(nodes.For):
        if node.recursive:
            raise ParameterError(f"report template {path.name} (line {node.lineno}): holds a "
                                 "recursive loop: a report template's loops are plain")

    def guard(name, args, lineno):
        # An environment attribute is no name a template can write, so none can replace it.
        return nodes.Call(nodes.EnvironmentAttribute(name), args, [], None, None, lineno=lineno)

    class Guards(NodeTransformer):
        def visit_For(self, node):
            self.generic_visit(node)
            node.iter = guard("crowdvib_loop", [node.iter], node.lineno)
            return node

        def visit_Concat(self, node):
            self.generic_visit(node)
            return guard("crowdvib_concat", node.nodes, node.lineno)

    tree = Guards().visit(tree)
    tree.set_environment(environment)
    return tree


def _embedded(template, name):
    """A file beside the template as a data: URI (Markup)."""
    found = child_path(template.parent, name)
    kind = None if found is None else _IMAGES.get(found.suffix.lower())
    if found is None or kind is None or not found.is_file():
        raise ParameterError(f"report template {template.name}: embed({name!r}) must name a "
                             f"{'/'.join(s[1:] for s in _IMAGES)} file beside the template")
    if found.stat().st_size > _MAX_EMBEDDED:
        raise ParameterError(f"report template {template.name}: embed({name!r}) names a file of "
                             f"{found.stat().st_size} bytes, more than a logo's "
                             f"{_MAX_EMBEDDED} bytes")
    data = base64.b64encode(found.read_bytes()).decode("ascii")
    return Markup(f"data:{kind};base64,{data}")
