"""The case-file key reference, generated from the parser itself (crowdvib/io/casefile.py and
its table readers: casemodels.py, casemeasurement.py, casedesign.py, casecomfort.py), and that of the ambient-test file of ``crowdvib modes`` (crowdvib/io/ambient.py).

Every key a case file may hold is read in the parser by a call such as
``table.number("window_length", 60.0, rule="positive")``. This extension reads those calls from
the parser's source (its syntax tree, so nothing can drift: a key added to the parser appears
here, one removed disappears) and writes ``generated/casefile_keys.rst``: one table per section
with each key's type, default, rule and unit. Units come from crowdvib.quantities, the one
table of quantities that the results, the report and the docs share.
"""

import ast
from pathlib import Path

#: Parser function → the case-file section its ``table`` argument is.
SECTIONS = {"_case": "case", "_structure": "structure", "_crowd": "crowd",
            "_crowd_profile": "crowd", "_density_uncertainty": "crowd", "_msd": "hsi",
            "measurement_spec": "measurement", "header_row_of": "measurement",
            "_estimation": "estimation",
            "_simulation": "simulation", "_outputs": "structure", "_output_nodes": "structure", "_design": "design",
            "_design_damper": "design.damper",
            "_measurement_block": "measurement", "_measurements": "case", "_report": "report",
            "_comfort": "comfort", "_traffic": "traffic"}
#: The same for the ambient-test file (crowdvib.io.ambient): parser function → the table each of
#: its variables is (the records' ``table`` is one [record] block).
AMBIENT_SECTIONS = {"read_ambient": {"root": "case"}, "_records": {"table": "record", "root": "case"},
                    "_output_nodes": {"table": "modal_model"}}
#: Table accessor → the TOML type it accepts.
KINDS = {"number": "number", "numbers": "number or list of numbers", "string": "string",
         "strings": "list of strings", "boolean": "boolean", "pair": "[lower, upper]",
         "file": "file path (relative to the TOML file)", "raw": "value (see rule)",
         "table": "table", "count": "integer"}
#: Rules the parser checks in code rather than in the accessor call (they take precedence).
RULES = {"structure.outputs": "a table name = position x [m] (or [x, y] across lanes)",
         "measurement.channels": "a table output name = \"channel in file\"",
         "measurement.time_frame": "[start, end] with start >= 0",
         "measurement.format": "a record format of the formats table (io.formats.FORMATS): "
                               "csv, npz, mat, mat73 or uff; default from the suffix",
         "measurement.overlap": "in [0, 1)", "measurement.filter.order": "an integer >= 1",
         "measurement.filter.cutoff": "> 0, or false for no filter",
         "estimation.level": "in (0, 1): a fraction, not percent",
         "crowd.density_uncertainty": "in [0, 0.5]: the relative standard uncertainty of the "
                                      "density, a fraction (0.1 for ±10 %)",
         "estimation.band": "lower < upper, lower >= 0",
         "estimation.outputs": "names of structure outputs (default all record channels)",
         "estimation.free_parameters": "[\"frequency\", \"damping_ratio\"], optionally "
                                       "\"mass_ratio\", optionally both "
                                       "\"step_frequency_mean\" and \"step_frequency_std\" "
                                       "(one record)",
         "estimation.weights": "one per entry of estimation.outputs, > 0",
         "crowd.density": "> 0; may be left out with counts or density_profile (then the "
                          "walkers' reference density is the profile's mean over its table)",
         "crowd.counts": "CSV of time [s], count: people on the deck from each time to the "
                         "next (density = count/(L·B)); a crowd that changes in the record",
         "crowd.density_profile": "CSV of time [s], density [persons/m²] (instead of counts)",
         "crowd.walking_speed": "> 0; default from Weidmann's speed–density relation",
         "crowd.step_frequency_mean": "> 0; default from Bruno & Venuti's speed relation",
         "structure.output_nodes": "a table output name = node number (FE exports; instead "
                                   "of outputs)",
         "structure.mode_shapes": "CSV of shapes along the walkway, or a CSV node table; left "
                                  "out when modal_table is a UFF file (it holds the shapes)",
         "report.measurement_date": "a date (2024-05-01, TOML's date) or text",
         "report.template": "a Jinja2 HTML page (.html or .j2) around the report, in the "
                            "case file's folder or below it (docs: Case files, [report])",
         "case.seed": "a non-negative integer", "case.name": "default: the file name",
         "case.force": "\"zivanovic\" (default), \"young\" or \"measured\" (the packaged "
                       "PhysioNet walks replayed; simulate only: no load PSD)",
         "design.codes": "registered codes (built in: setra, hivoss, en1990, ukna)",
         "design.comfort_class": "CL1, CL2 or CL3",
         "design.gamma_figure": "\"pd6688-2\" (PD 6688-2:2011 Figure 2, the default) or "
                                "\"na9\" (Figure NA.9 as published); UK NA only",
         "design.neq_damping": "\"occupied\" (the default) or \"empty\": the damping ratio "
                               "of n_eq; Sétra, HiVoSS, EN 1990",
         "design.site_factors.k1": "a number > 0 or a named choice (UK NA, NA.2.44.6)",
         "design.site_factors.k2": "a number > 0 or a named choice (UK NA, NA.2.44.6)",
         "design.site_factors.k3": "a number > 0 or a named choice (UK NA, NA.2.44.6)",
         "design.site_factors.k4": "a number > 0 or a named choice (UK NA, NA.2.44.6)",
         "design.damper.mode": "an integer >= 1; with mass_ratio instead of an explicit "
                               "damper (tuned to the structure)",
         "case.measurement": "one [measurement] table, or several [[measurement]] blocks "
                             "(one MSD fitted to all, each block with its own name and "
                             "[measurement.crowd])",
         "measurement.name": "the block's label in a joint fit (default \"record N\")",
         "measurement.units": "\"m/s2\" (also m/s^2, m/s², m s-2, mps2), \"g\" (also g0; "
                              "g = 9.81 m/s²), \"mg\" or \"mm/s2\"; default: the units the "
                              "file states (a comment, or its column headers: \"a [mg]\"), "
                              "else m/s2",
         "measurement.header_row": "CSV: the line number (from 1) of the header row, below a "
                                   "logger's metadata lines; default: the first line naming "
                                   "as many columns as the rows below it hold numbers",
         "measurement.skip_rows": "CSV: the lines above the header row (instead of "
                                  "header_row = skip_rows + 1)",
         "measurement.gaps": "a dropout (empty cells): \"cut\" keeps the longest stretch "
                             "without one, \"bridge\" interpolates each up to max_gap; "
                             "default: refused; the results state what was done",
         "measurement.max_gap": "> 0; the longest dropout gaps = \"bridge\" interpolates",
         "structure.n_modes": "an integer >= 1: the first n sine modes",
         "case.record": "one [record] table, or several [[record]] blocks (setups; they share "
                        "one sample rate)",
         "record.channels": "the sensors in order (default all channels), or a table sensor = "
                            "\"channel in file\" (renames them)",
         "record.sample_rate": "> 0; for a CSV without a time column",
         "identification.reference_channels": "with several [[record]] blocks only, and then "
                                              "required: the channels every record shares",
         "identification.frequency_band": "lower < upper",
         "identification.n_modes": "an integer >= 1; default every consistently stable mode",
         "identification.max_order": "an integer >= 2; SSI-cov's largest model order",
         "identification.segment_length": "an integer >= 64; EFDD's Welch segment",
         "modal_model.output_nodes": "a table sensor = node number of fe_model",
         "modal_model.fe_model": "an FE export (UFF 15 + 55) whose paired modes take the "
                                 "identified f and ξ; or modal_masses instead",
         "modal_model.modal_masses": "> 0, one per identified mode (with sensor_positions and "
                                     "walkway instead of fe_model)",
         "modal_model.sensor_positions": "one per sensor, in the order of the sensors",
         "modal_model.walkway": "[start, end] of the walkway",
         "comfort.simulate_below": ">= 0; default: a thin crowd, 100 walkers over the "
                                   "walkway's area (docs: theory, A year of comfort); 0: none"}
#: Units of keys whose name alone does not find them in crowdvib.quantities (a damper's mass
#: is not a modal mass, its position is along the walkway, its lane across it).
UNITS = {"design.damper.mass": "kg", "design.damper.position": "m", "design.damper.lane": "m",
         "measurement.resample": "Hz", "measurement.max_gap": "s", "identification.frequency_band": "Hz",
         "identification.segment_length": "samples", "modal_model.modal_masses": "kg",
         "modal_model.sensor_positions": "m", "modal_model.walkway": "m"}


def _literal(node):
    try:
        return ast.literal_eval(node)
    except ValueError:
        return None


def _text(value):
    if value is None:
        return "—"
    return f"``{value!r}``" if not isinstance(value, str) else f"``\"{value}\"``"


def _conditions(function):
    """Node → the form of the table it is read in: ``type = "…"`` for the branches of
    ``if kind == "…"`` (kind read with choices), ``key is given / left out`` for
    ``if table.has(key)``."""
    choices = {}
    for node in ast.walk(function):
        if (isinstance(node, ast.Assign) and isinstance(node.targets[0], ast.Name)
                and isinstance(node.value, ast.Call)
                and isinstance(node.value.func, ast.Attribute) and node.value.args):
            options = {k.arg: _literal(k.value) for k in node.value.keywords}
            if options.get("choices"):
                choices[node.targets[0].id] = (_literal(node.value.args[0]), options["choices"])
    labels = {}
    for node in ast.walk(function):
        if not isinstance(node, ast.If):
            continue
        test, body, orelse = node.test, None, None
        if (isinstance(test, ast.Compare) and isinstance(test.left, ast.Name)
                and test.left.id in choices and isinstance(test.ops[0], ast.Eq)):
            key, values = choices[test.left.id]
            value = _literal(test.comparators[0])
            others = [v for v in values if v != value]
            body = f"{key} = \"{value}\""
            orelse = f"{key} = \"{others[0]}\"" if len(others) == 1 else f"{key} ≠ \"{value}\""
        elif (isinstance(test, ast.Call) and isinstance(test.func, ast.Attribute)
                and test.func.attr == "has" and test.args):
            key = _literal(test.args[0])
            body, orelse = f"``{key}`` is given", f"``{key}`` is left out"
        for label, branch in ((body, node.body), (orelse, node.orelse)):
            for statement in branch if label else ():
                for inner in ast.walk(statement):
                    labels.setdefault(id(inner), label)
    return labels


def _integer_reads(function):
    """Accessor calls whose value the parser takes as ``int(…)``: counts, not numbers."""
    return {id(node.args[0]) for node in ast.walk(function)
            if isinstance(node, ast.Call) and isinstance(node.func, ast.Name)
            and node.func.id == "int" and node.args and isinstance(node.args[0], ast.Call)}


def parser_keys(source, sections=None):
    """``(section.key, kind, default, required, rule)`` for every key the parser reads.

    ``required`` is False, True, or the form of the table in which the key is required
    (``type = "simply_supported_beam"``); a key read in one form only says so in its rule.
    """
    sections = SECTIONS if sections is None else sections
    tree = ast.parse(source)
    keys = {}
    for function in tree.body:
        if not isinstance(function, ast.FunctionDef) or function.name not in sections:
            continue
        section = sections[function.name]
        prefixes = dict(section) if isinstance(section, dict) else {"table": section,
                                                                    "root": section}
        forms, integers = _conditions(function), _integer_reads(function)
        for node in ast.walk(function):
            # sub = table.table("name"): sub's keys live under section.name
            if isinstance(node, ast.Assign) and isinstance(node.value, ast.Call):
                call = node.value
                if (isinstance(call.func, ast.Attribute) and call.func.attr == "table"
                        and isinstance(call.func.value, ast.Name)
                        and call.func.value.id in prefixes and call.args):
                    parent, name = prefixes[call.func.value.id], _literal(call.args[0])
                    # a table of the top level is a section of its own
                    prefixes[node.targets[0].id] = name if parent == "case" else f"{parent}.{name}"
        for node in ast.walk(function):
            if not isinstance(node, ast.Call):
                continue
            func = node.func
            if (isinstance(func, ast.Name) and func.id in ("_bounds", "_starts", "_count")
                    and node.args):
                _special(func.id, node, prefixes, keys)
                continue
            if not (isinstance(func, ast.Attribute) and func.attr in KINDS
                    and isinstance(func.value, ast.Name) and func.value.id in prefixes
                    and node.args and isinstance(node.args[0], ast.Constant)):
                continue
            name = f"{prefixes[func.value.id]}.{node.args[0].value}"
            if func.attr == "table" or name in keys and keys[name][0] != KINDS["raw"]:
                continue
            required = len(node.args) < 2 and func.attr not in ("boolean", "table")
            default = None if required else _literal(node.args[1]) if len(node.args) > 1 else None
            if name in keys:                  # raw(name, default) first, then a typed read
                required, default = keys[name][2], keys[name][1]
            options = {k.arg: _literal(k.value) for k in node.keywords}
            rule = (f"one of {', '.join(map(repr, options['choices']))}"
                    if options.get("choices") else options.get("rule") or "")
            rule = RULES.get(name) or {"positive": "> 0", "non_negative": ">= 0",
                                       "fraction": "in (0, 1)"}.get(rule, rule)
            kind = KINDS[func.attr]
            if id(node) in integers or rule.startswith("an integer"):
                kind = "integer"                # read as a float, kept as int(…)
                default = None if default is None else int(default)
            form = forms.get(id(node))
            if form and f"``{name.split('.')[-1]}``" in form:
                required = False        # read only if given: the key that picks the form
            # "only when step_frequencies is given" says nothing of step_frequencies.cutoff
            elif form and not any(f"``{part}``" in form for part in name.split(".")[1:-1]):
                required = form if required else False
                rule = f"{rule}; only when {form}" if rule else f"only when {form}"
            keys[name] = (kind, default, required, rule)
    return keys


def _special(helper, node, prefixes, keys):
    """``_bounds(table.table("bounds"), (keys…))``, ``_starts(table, "starts", sizes)`` and
    ``_count(table, "name", default, least)`` (an integer >= least)."""
    if helper == "_count":
        table, name, default, least = node.args[0], *map(_literal, node.args[1:4])
        if isinstance(table, ast.Name) and table.id in prefixes:
            keys[f"{prefixes[table.id]}.{name}"] = ("integer", default, False,
                                                    RULES.get(f"{prefixes[table.id]}.{name}")
                                                    or f"an integer >= {least}")
        return
    if helper == "_starts":
        table, name, sizes = node.args[0], _literal(node.args[1]), _literal(node.args[2])
        if isinstance(table, ast.Name) and table.id in prefixes:
            keys[f"{prefixes[table.id]}.{name}"] = (
                "list of points", None, False,
                f"points of {' or '.join(map(str, sizes))} values (f_h1 [Hz], ξ_h1[, μ_h1])")
        return
    inner, names = node.args[0], _literal(node.args[1])
    if (isinstance(inner, ast.Call) and isinstance(inner.func, ast.Attribute)
            and isinstance(inner.func.value, ast.Name) and inner.func.value.id in prefixes):
        prefix = f"{prefixes[inner.func.value.id]}.{_literal(inner.args[0])}"
        for name in names:
            keys[f"{prefix}.{name}"] = ("[lower, upper]", None, False, "0 < lower < upper")


#: The modules whose functions read the case-file keys.
PARSER_MODULES = ("crowdvib.io.casefile", "crowdvib.io.casemodels",
                  "crowdvib.io.casemeasurement", "crowdvib.io.casedesign",
                  "crowdvib.io.casecomfort")


def parser_sources():
    """Paths of the parser modules' source files."""
    import importlib

    return [importlib.import_module(name).__file__ for name in PARSER_MODULES]


#: The case file's sections in the order of the reference.
CASE_ORDER = ("case", "structure", "crowd", "hsi", "measurement", "estimation", "simulation",
              "design", "comfort", "traffic", "report")


def write_reference(source_paths, units, target, sections=None, order=CASE_ORDER):
    """Write the reST reference of every key the parser modules read to ``target``
    (``sections``: as :func:`parser_keys`; ``order``: the sections in the order printed)."""
    keys = {}
    for path in [source_paths] if isinstance(source_paths, (str, Path)) else source_paths:
        keys.update(parser_keys(Path(path).read_text(encoding="utf-8"), sections))
    sections = {}
    for name, row in sorted(keys.items()):
        section, _, key = name.partition(".")
        sections.setdefault(section, []).append((key, *row))
    lines = [".. This file is generated by docs/_ext/casefile_keys.py from the parser; "
             "do not edit.", ""]
    for section in order:
        title = "top level" if section == "case" else f"``[{section}]``"
        lines += [title, "^" * len(title), "",
                  ".. list-table::", "   :header-rows: 1", "   :widths: 22 18 12 10 38", "",
                  "   * - key", "     - type", "     - default", "     - unit", "     - rule"]
        for key, kind, default, required, rule in sections.get(section, []):
            unit = units.get(key.rpartition(".")[2], ("", ""))[1]
            unit = UNITS.get(f"{section}.{key}", unit)
            need = (f"*required* when {required}" if isinstance(required, str)
                    else "*required*" if required else _text(default))
            lines += [f"   * - ``{key}``", f"     - {kind}", f"     - {need}",
                      f"     - {unit or '—'}", f"     - {rule or '—'}"]
        lines.append("")
    Path(target).parent.mkdir(parents=True, exist_ok=True)
    Path(target).write_text("\n".join(lines), encoding="utf-8")
    return keys


def _generate(app):
    from crowdvib.quantities import QUANTITIES

    import crowdvib.io.ambient

    write_reference(parser_sources(), QUANTITIES,
                    Path(app.srcdir) / "generated" / "casefile_keys.rst")
    write_reference(crowdvib.io.ambient.__file__, QUANTITIES,
                    Path(app.srcdir) / "generated" / "ambient_keys.rst", AMBIENT_SECTIONS,
                    ("case", "record", "identification", "modal_model"))


def setup(app):
    app.connect("builder-inited", _generate)
    return {"parallel_read_safe": True}
