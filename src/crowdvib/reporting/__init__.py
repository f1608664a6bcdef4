"""Figures (``plotting``, the only place matplotlib is imported, lazily) and the HTML report."""
