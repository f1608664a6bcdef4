"""Text from a file made safe for a terminal (issue 35 §1).

A name or value read from someone else's file reaches the user inside messages. Raw, its control
characters act on the terminal: ``ESC ] 0 ; … BEL`` retitles the window, ``ESC [ 2 J`` clears
it, U+202E turns the rest of the line around. :func:`terminal_safe` writes each of them as a
Python escape (``\\x1b``, ``\\u202e``), the rest of the text unchanged; the command line passes
every line it prints through it, and the readers' messages quote file content through it.
"""

import re

__all__ = ["terminal_safe", "excerpt"]

#: C0 controls but tab and newline, DEL, C1 controls, and the bidirectional marks, embeddings,
#: overrides and isolates (and the line and paragraph separators, which break a line).
_UNSAFE = re.compile("[\x00-\x08\x0b-\x1f\x7f-\x9f\u061c\u200e\u200f\u2028\u2029"
                     "\u202a-\u202e\u2066-\u2069]")


def _escaped(found):
    return repr(found.group())[1:-1]        # '\x1b' → \x1b, '\u202e' → \u202e


def terminal_safe(text, *, newlines=True):
    """``text`` with every terminal control and bidi override written as an escape.

    Tab and (with ``newlines``) newline are kept: the messages' own layout. A carriage return,
    which would let a line overwrite itself, is always escaped.
    """
    text = _UNSAFE.sub(_escaped, str(text))
    return text if newlines else text.replace("\n", "\\n")


def excerpt(text, limit=40):
    """At most ``limit`` characters of a foreign file's text, escaped, as one quoted line."""
    text = str(text)
    short = text[:limit] + ("…" if len(text) > limit else "")
    return f"'{terminal_safe(short, newlines=False)}'"
