"""Reporting: figures (each returns a matplotlib Figure), tables and the HTML report."""
