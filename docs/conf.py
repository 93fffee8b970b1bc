"""Sphinx configuration of spacepol's documentation (built with warnings as errors by ``tests/test_docs.py``)."""

from __future__ import annotations

from docutils import nodes
from docutils.parsers.rst import Directive

project = "spacepol"
author = "spacepol developers"
copyright = "spacepol developers"
extensions = ["myst_parser", "sphinx.ext.autodoc", "sphinx.ext.napoleon", "sphinxarg.ext"]
source_suffix = {".md": "markdown"}
exclude_patterns = ["_build"]
html_theme = "furo"
html_title = "spacepol"
myst_heading_anchors = 3
autodoc_member_order = "bysource"
autodoc_default_options = {"members": True, "undoc-members": False}
napoleon_numpy_docstring = True
napoleon_google_docstring = False
# the docstrings are prose with ``literals``, not reST cross-references to every type they name
nitpicky = False


class EffectsTable(Directive):
    """``effects-table``: every registered effect (name, what it adds, its parameters with priors and units), read
    from the registry at build time, so the table cannot drift from the code."""

    def run(self):
        from spacepol.physics.registry import registry

        table = nodes.table()
        group = nodes.tgroup(cols=3)
        table += group
        for width in (14, 56, 30):
            group += nodes.colspec(colwidth=width)
        head = nodes.thead()
        group += head
        head += self._row(["effect", "what it adds", "parameters (prior; unit)"])
        body = nodes.tbody()
        group += body
        for name in registry.names():
            cls = registry.get(name)
            params = "; ".join(f"{p.name} {p.prior!r}" + (f" [{p.unit}]" if p.unit else "") for p in cls.parameters)
            body += self._row([name, " ".join(cls.description.split()), params or "none"])
        return [table]

    @staticmethod
    def _row(cells):
        row = nodes.row()
        for text in cells:
            entry = nodes.entry()
            entry += nodes.paragraph(text=text)
            row += entry
        return row


def setup(app):
    app.add_directive("effects-table", EffectsTable)
    return {"parallel_read_safe": True}
