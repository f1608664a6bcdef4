"""The notebook view of a result (:meth:`crowdvib.cases.Results._repr_html_`): its headline
values, its own table and its verdict (issue 36 §1: the view of a check or a simulation held an
empty table, a season's only J/J_noHSI).

Every value is escaped; the view needs no pandas.
"""

import html

__all__ = ["results_html", "MAX_ROWS"]

#: Rows of a result's table the view shows; the others are counted below it.
MAX_ROWS = 20
_MARKS = {"ok": "✓", "doubt": "?", "fail": "✗"}
_LEFT = "style='text-align:left'"


def results_html(results, table=(), columns=()):
    """The notebook view of ``results``.

    Parameters
    ----------
    results : Results
        Its ``_headline()`` rows (quantity, value) and its verdict are shown.
    table : sequence of dict
        The kind's own table (``results.table()`` of the kinds that have one), shown below the
        headline, its first :data:`MAX_ROWS` rows.
    columns : sequence of str
        The columns of ``table`` to show (default: every key, in the order of the rows).

    Returns
    -------
    str
    """
    cells = "".join(f"<tr><th {_LEFT}>{html.escape(k)}</th><td {_LEFT}>{html.escape(v)}</td>"
                    "</tr>" for k, v in results._headline())
    found = "".join(f"<li>{_MARKS[f.severity]} {html.escape(f.text)}</li>"
                    for f in results.verdict())
    state = ("check before use: the result is in doubt" if results.in_doubt
             else "the bridge fails a design check" if results.fails_design
             else "no warnings")
    return (f"<div><strong>crowdvib {html.escape(results.command)}: "
            f"{html.escape(results.name)}</strong>{f'<table>{cells}</table>' if cells else ''}"
            f"{_table(list(table), columns)}<p>Verdict: {state}</p><ul>{found}</ul></div>")


def _table(rows, columns):
    if not rows:
        return ""
    columns = list(columns) or list(dict.fromkeys(key for row in rows for key in row))
    head = "".join(f"<th>{html.escape(str(c))}</th>" for c in columns)
    body = "".join("<tr>" + "".join(f"<td>{html.escape(_cell(row.get(c)))}</td>"
                                    for c in columns) + "</tr>" for row in rows[:MAX_ROWS])
    more = (f"<p>… and {len(rows) - MAX_ROWS} more row(s): <code>to_dataframe()</code> has "
            "them all.</p>" if len(rows) > MAX_ROWS else "")
    return f"<table><thead><tr>{head}</tr></thead><tbody>{body}</tbody></table>{more}"


def _cell(value):
    """A value as the view shows it: numbers to four digits, nothing as —."""
    if value is None:
        return "—"
    if isinstance(value, bool):
        return "yes" if value else "no"
    if isinstance(value, float):
        return f"{value:.4g}"
    if isinstance(value, (list, tuple)):
        return ", ".join(_cell(v) for v in value)
    if isinstance(value, dict):
        return ", ".join(f"{k}: {_cell(v)}" for k, v in value.items())
    return str(value)
