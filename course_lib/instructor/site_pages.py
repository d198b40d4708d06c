"""Pages of the static site: one HTML page per executed notebook, and the index.

A page is nbconvert's JupyterLab template (it looks like the notebook in JupyterLab) with
three changes, made by a small template kept here as a string: MathJax 3 loaded from the
site's own ``_static`` folder (not a CDN), no Mermaid loader (the course has no diagrams:
the stock template names a CDN), and a navigation bar. require.js and the widget manager
come from ``_static`` too (:mod:`course_lib.instructor.site_assets`), so a page works from
a folder opened without a network.

Reader pages hide the exercise answers: a cell with a solution region shows the student's
stub and no output (its output is the check's verdict on the answer); every other cell keeps
its output, since later cells use ``course_lib``, never the student's answer. Imports
nbconvert, nbformat, jinja2 and :mod:`course_lib.instructor.notebooks`.
"""

from __future__ import annotations

import copy
import html
import re
from pathlib import Path

import nbformat

from .notebooks import BEGIN, strip_solution
from .site_assets import MATHJAX_JS, REQUIRE_JS, SRE_FEATURE_JS, WIDGETS_JS

_TEMPLATE = r"""{%- extends 'lab/index.html.j2' -%}
{%- block html_head_js_mathjax -%}
<script>
window.MathJax = {
  tex: {inlineMath: [['$', '$'], ['\\(', '\\)']], displayMath: [['$$', '$$'], ['\\[', '\\]']],
        processEscapes: true, processEnvironments: true, tags: 'ams'},
  options: {ignoreHtmlClass: 'tex2jax_ignore', processHtmlClass: 'tex2jax_process'},
  startup: {ready: function () { MathJax.startup.defaultReady(); MathJax.Hub = hub; }}
};
// The widget manager typesets labels with MathJax 2's call, MathJax.Hub.Queue(["Typeset",
// MathJax.Hub, element]): answer it with MathJax 3's typesetPromise.
var hub = {Queue: function () {
  for (var i = 0; i < arguments.length; i++) {
    var a = arguments[i];
    if (a && a[0] === 'Typeset' && a[2] && window.MathJax.typesetPromise) {
      window.MathJax.typesetPromise([a[2]]).catch(function () {});
    }
  }
}};
window.MathJax.Hub = hub;
</script>
<script>{{ resources.sre_feature_js }}</script>
<script async id="MathJax-script" src="{{ resources.mathjax_url }}"></script>
{%- endblock html_head_js_mathjax -%}
{%- block html_head_js_mermaidjs -%}{%- endblock html_head_js_mermaidjs -%}
{% block extra_css %}<style>{{ resources.course_css }}</style>{% endblock extra_css %}
{%- block body_header -%}
{{ super() }}
<nav class="course-nav">{{ resources.course_nav }}</nav>
{%- endblock body_header -%}
{% block body_footer %}
<nav class="course-nav course-nav-bottom">{{ resources.course_nav }}</nav>
{{ super() }}
{% endblock body_footer %}
"""

NAV_CSS = (
    ".course-nav{display:flex;gap:1.5em;flex-wrap:wrap;padding:8px 16px;margin:0 0 8px;"
    "border-bottom:1px solid #ddd;font:14px/1.4 system-ui,sans-serif;background:#fafafa}"
    ".course-nav-bottom{border-top:1px solid #ddd;border-bottom:0;margin:16px 0 0}"
    ".course-nav a{color:#1a5fb4;text-decoration:none}.course-nav a:hover{text-decoration:underline}"
    ".course-nav .here{font-weight:600}"
    ".jupyter-widgets,.widget-label,.widget-readout{font-family:system-ui,-apple-system,"
    "'Segoe UI',Roboto,sans-serif}"
)

_INDEX = """<!DOCTYPE html>
<html lang="en"><head><meta charset="utf-8">
<meta name="viewport" content="width=device-width, initial-scale=1">
<title>{title}</title>
<style>
body{{font:16px/1.55 system-ui,-apple-system,'Segoe UI',Roboto,sans-serif;max-width:60em;
margin:2em auto;padding:0 1em;color:#222}}
table{{border-collapse:collapse;margin:1em 0}}td,th{{border-bottom:1px solid #ddd;
padding:6px 10px;vertical-align:top;text-align:left}}th{{background:#f4f4f4}}
code{{font-size:90%}}a{{color:#1a5fb4}}.note{{color:#555;font-size:14px}}
</style></head>
<body>
<h1>{title}</h1>
{intro}
{table}
<p class="note">{note}</p>
</body></html>
"""


def title_of(nb: nbformat.NotebookNode, fallback: str) -> str:
    """The first ``# heading`` of the notebook's markdown, else ``fallback``."""
    for cell in nb.cells:
        if cell.cell_type == "markdown":
            m = re.search(r"^#\s+(.+)$", cell.source, re.M)
            if m:
                return m.group(1).strip()
    return fallback


def reader_version(nb: nbformat.NotebookNode, name: str = "notebook") -> nbformat.NotebookNode:
    """A copy of an executed solution notebook with the exercise answers hidden.

    Cells holding a solution region get the student's stub and lose their outputs; other
    cells are unchanged.
    """
    nb = copy.deepcopy(nb)
    for index, cell in enumerate(nb.cells):
        if BEGIN not in cell.source:
            continue
        code = cell.cell_type == "code"
        cell.source = strip_solution(cell.source, code=code, where=f"{name}, cell {index}")
        if code:
            cell.outputs = []
            cell.execution_count = None
    return nb


def drop_stateless_widgets(nb: nbformat.NotebookNode) -> int:
    """Remove widget views whose state is not stored (they would show as
    ``VBox(children=...)`` text); return how many were removed."""
    state = nb.metadata.get("widgets", {}).get("application/vnd.jupyter.widget-state+json", {})
    known = set(state.get("state", {}))
    removed = 0
    for cell in nb.cells:
        if cell.cell_type != "code":
            continue
        keep = []
        for out in cell.outputs:
            view = out.get("data", {}).get("application/vnd.jupyter.widget-view+json")
            if view is not None and view.get("model_id") not in known:
                removed += 1
                continue
            keep.append(out)
        cell.outputs = keep
    return removed


def nav_html(pages: list[tuple[str, str]], here: str | None) -> str:
    """Links to the index and to each page (``(stem, title)``), the current one marked."""
    links = ['<a href="index.html">Contents</a>']
    names = [stem for stem, _ in pages]
    if here in names:
        k = names.index(here)
        if k > 0:
            links.append(f'<a href="{names[k - 1]}.html">&larr; {html.escape(pages[k - 1][1])}</a>')
        if k + 1 < len(pages):
            links.append(f'<a href="{names[k + 1]}.html">{html.escape(pages[k + 1][1])} &rarr;</a>')
    return " ".join(links)


def _exporter():
    from jinja2 import DictLoader
    from nbconvert import HTMLExporter

    return HTMLExporter(
        template_name="lab", template_file="course_page.html.j2",
        extra_loaders=[DictLoader({"course_page.html.j2": _TEMPLATE})],
        require_js_url=REQUIRE_JS, mathjax_url=MATHJAX_JS, widget_renderer_url=WIDGETS_JS,
        jupyter_widgets_base_url="_static/", html_manager_semver_range="1.0.15",
    )


def notebook_page(nb: nbformat.NotebookNode, stem: str, nav: str) -> str:
    """The HTML page of an (already executed, already filtered) notebook."""
    body, _ = _exporter().from_notebook_node(
        nb, resources={"metadata": {"name": title_of(nb, stem)}, "course_nav": nav,
                       "course_css": NAV_CSS, "sre_feature_js": SRE_FEATURE_JS})
    # links between notebooks point at their pages
    return re.sub(r'href="(\./)?(\d\d_[A-Za-z0-9_]+)\.ipynb', r'href="\2.html', body)


def index_page(readme: Path, pages: list[tuple[str, str]], *, solutions: bool) -> str:
    """The index: the README's title, first paragraph and notebook table, linked to pages."""
    from nbconvert.filters.markdown_mistune import markdown2html_mistune

    text = Path(readme).read_text(encoding="utf-8")
    title = re.search(r"^#\s+(.+)$", text, re.M).group(1).strip()
    intro = text.split("\n\n")[1] if "\n\n" in text else ""
    section = re.search(r"^## The notebooks\s*\n(.*?)(?=^## )", text, re.M | re.S)
    rows = section.group(1) if section else ""
    table_lines = [ln for ln in rows.splitlines() if ln.startswith("|")]
    published = {stem for stem, _ in pages}

    def link(m: re.Match) -> str:
        stem = m.group(1)
        return f"[`{stem}`]({stem}.html)" if stem in published else m.group(0)

    table_md = re.sub(r"`(\d\d_[A-Za-z0-9_]+)`", link, "\n".join(table_lines))
    if not table_lines:  # no table in the README: list the pages
        table_md = "\n".join(f"- [{t}]({s}.html)" for s, t in pages)
    note = ("Pages show the executed solutions, exercise answers included."
            if solutions else
            "Pages show every figure, animation and explorer of the executed notebooks; "
            "exercise answers are hidden (open the notebooks in JupyterLab to work them).")
    note += " Everything here works without a network and without a running kernel."
    return _INDEX.format(title=html.escape(title), intro=markdown2html_mistune(intro),
                         table=markdown2html_mistune(table_md), note=note)
