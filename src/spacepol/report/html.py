"""A self-contained HTML report: figures embedded as base64 PNG, tables, findings."""

from __future__ import annotations

import base64
import html
import io


def figure_to_data_uri(fig) -> str:
    """A Matplotlib figure as an embeddable PNG data URI."""
    buf = io.BytesIO()
    fig.savefig(buf, format="png", dpi=110, bbox_inches="tight")
    return "data:image/png;base64," + base64.b64encode(buf.getvalue()).decode()


def png_file_to_data_uri(path) -> str:
    """A PNG file as an embeddable data URI."""
    return "data:image/png;base64," + base64.b64encode(open(path, "rb").read()).decode()


def table(header, rows) -> str:
    """An HTML table of ``header`` and ``rows`` (cells escaped)."""
    head = "".join(f"<th>{html.escape(str(h))}</th>" for h in header)
    body = "".join("<tr>" + "".join(f"<td>{html.escape(str(c))}</td>" for c in row) + "</tr>" for row in rows)
    return f"<table><thead><tr>{head}</tr></thead><tbody>{body}</tbody></table>"


def paragraph(text) -> str:
    """An HTML paragraph of escaped text."""
    return f"<p>{html.escape(text)}</p>"


def bullets(items) -> str:
    """An HTML list of escaped items (empty for none)."""
    return "<ul>" + "".join(f"<li>{html.escape(i)}</li>" for i in items) + "</ul>"


def image(uri, caption="") -> str:
    """An HTML image of a data URI."""
    cap = f"<figcaption>{html.escape(caption)}</figcaption>" if caption else ""
    return f'<figure><img src="{uri}" style="max-width:100%">{cap}</figure>'


def page(title, sections) -> str:
    """sections: list of (heading, html body)."""
    style = ("body{font-family:sans-serif;max-width:1100px;margin:2em auto;color:#222}"
             "table{border-collapse:collapse;margin:0.5em 0}td,th{border:1px solid #bbb;padding:3px 8px;"
             "text-align:right;font-size:90%}th{background:#eee}h2{border-bottom:1px solid #ccc}"
             ".warn{color:#a40}")
    body = "".join(f"<h2>{html.escape(h)}</h2>{b}" for h, b in sections)
    return (f"<!DOCTYPE html><html><head><meta charset='utf-8'><title>{html.escape(title)}</title>"
            f"<style>{style}</style></head><body><h1>{html.escape(title)}</h1>{body}</body></html>")
