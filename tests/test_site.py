"""`make site`: reader pages hide answers, pages load nothing from the network, the index
links the README's table, kernel-free explorers are added beside widgets, and a small site
builds from the vendored npm assets, executed or not. (The browser checks live in tests/browser.)"""

import shutil

import matplotlib
import nbformat
import pytest
from notebook_helpers import ROOT

from course_lib.instructor import site, site_pages
from course_lib.instructor.notebooks import BEGIN

matplotlib.use("agg")
WIDGET = "application/vnd.jupyter.widget-view+json"


def _solution(name: str) -> nbformat.NotebookNode:
    return nbformat.read(ROOT / "solutions" / f"{name}.ipynb", as_version=4)


def test_reader_version_hides_answers_and_keeps_every_other_output():
    nb = _solution("02_forward_euler")
    reader = site_pages.reader_version(nb, "02")
    exercises = [i for i, c in enumerate(nb.cells) if BEGIN in c.source]
    assert exercises, "notebook 02 has exercises"
    for i, (before, after) in enumerate(zip(nb.cells, reader.cells, strict=True)):
        assert BEGIN not in after.source
        if i in exercises and after.cell_type == "code":
            assert "raise NotImplementedError()" in after.source and after.outputs == []
        elif after.cell_type == "code":
            assert after.outputs == before.outputs
    assert any(BEGIN in c.source for c in nb.cells), "the input is not modified"


def test_page_loads_only_vendored_assets_and_links_pages():
    nb = nbformat.v4.new_notebook(cells=[
        nbformat.v4.new_markdown_cell("# Title\n\nSee [notebook 05](05_newtons_second_law.ipynb); "
                                      "$x^2$ and $$\\int_0^1 f\\,dt$$"),
        nbformat.v4.new_code_cell("1 + 1")])
    html = site_pages.notebook_page(nb, "00_test", site_pages.nav_html([("00_test", "Title")],
                                                                        "00_test"))
    assert site.REMOTE_ASSET.search(html) is None
    for url in ("_static/require.js", "_static/mathjax/tex-chtml-full.js"):
        assert f'src="{url}"' in html
    assert 'href="05_newtons_second_law.html"' in html
    assert "MathJax.Hub = hub" in html  # the widget manager's MathJax 2 call is answered
    assert "<title>Title</title>" in html and 'href="index.html"' in html


def test_offline_check_flags_assets_but_not_links(tmp_path):
    (tmp_path / "a.html").write_text('<a href="https://doi.org/x">paper</a><img src="data:,">')
    (tmp_path / "b.html").write_text("<script src='https://cdn.example/x.js'></script>")
    (tmp_path / "c.html").write_text('<link rel="stylesheet" href="//cdn.example/x.css">')
    assert [p.rsplit("/", 1)[1] for p in site.check_offline(tmp_path)] == ["b.html", "c.html"]


def test_index_links_the_readme_table_to_the_pages():
    pages = [("01_vector_fields", "01"), ("03_stability", "03")]
    html = site_pages.index_page(ROOT / "README.md", pages, solutions=False)
    assert '<a href="01_vector_fields.html"><code>01_vector_fields</code></a>' in html
    assert '<a href="03_stability.html">' in html and '<a href="02_forward_euler.html">' not in html
    assert "<table>" in html and "answers are hidden" in html


def test_explorer_is_added_beside_the_widget_once_and_stateless_views_are_dropped():
    nb = _solution("03_stability")
    widget_cells = [i for i, c in enumerate(nb.cells) if c.cell_type == "code"
                    and any(WIDGET in o.get("data", {}) for o in c.outputs)]
    assert len(widget_cells) == 1
    had = site.has_player(nb)
    added = site.add_player(nb, "03_stability")
    assert added != had and site.has_player(nb)
    if added:
        assert "stability_player" in nb.cells[widget_cells[0] + 1].source
    assert site.add_player(nb, "03_stability") is False
    assert site_pages.drop_stateless_widgets(nb) == 1  # stored notebooks keep no widget state
    assert not any(WIDGET in o.get("data", {}) for c in nb.cells if c.cell_type == "code"
                   for o in c.outputs)


@pytest.mark.skipif(shutil.which("npm") is None, reason="npm is needed to vendor the site's assets")
@pytest.mark.parametrize("stem", ["03_stability", "07_springs", "08_hair_chains", "10_flocking"])
def test_a_notebook_that_embeds_its_player_gets_no_second_copy(stem):
    from course_lib.lessons import kernel_free

    nb = _solution(stem)
    calls = [i for i, c in enumerate(nb.cells) if c.cell_type == "code"
             and f"kernel_free.{kernel_free.PLAYERS[stem].__name__}(" in c.source]
    assert len(calls) == 1, f"{stem} embeds its player in one cell"
    assert site.has_player(nb) and site.add_player(nb, stem) is False
    # not executed (no outputs, e.g. a student notebook): the same cell gets the player
    for cell in nb.cells:
        if cell.cell_type == "code":
            cell.outputs = []
    n_cells = len(nb.cells)
    if stem == "03_stability":      # the fastest player: build one for real
        assert site.add_player(nb, stem) is True
        assert len(nb.cells) == n_cells and site.has_player(nb)
        assert 'data-kind="parameter"' in nb.cells[calls[0]].outputs[0]["data"]["text/html"]


def test_small_site_builds_offline_from_the_vendored_assets(tmp_path):
    out = tmp_path / "site"
    pages = site.build(out, ROOT / "solutions", only=["02_forward_euler"], run=False,
                       log=lambda *a: None)
    assert [p.name for p in pages] == ["index.html", "02_forward_euler.html"]
    for asset in ("require.js", "html-manager/embed-amd.js", "mathjax/tex-chtml-full.js",
                  "mathjax/output/chtml/fonts/woff-v2/MathJax_Main-Regular.woff"):
        assert (out / "_static" / asset).stat().st_size > 1000, asset
    assert site.check_offline(out) == []
    assert "YOUR CODE HERE" in (out / "02_forward_euler.html").read_text()


def test_cli_names_the_valid_notebooks(tmp_path, capsys):
    assert site.main(["--only", "99_nope", "--no-execute", "--out", str(tmp_path / "s")]) == 1
    err = capsys.readouterr().err
    assert "99_nope" in err and "02_forward_euler" in err


def _write_notebook(path, *cells) -> None:
    nbformat.write(nbformat.v4.new_notebook(cells=list(cells), metadata={"kernelspec": {
        "name": "python3", "display_name": "Python 3", "language": "python"}}), path)


def test_build_executes_the_notebooks_and_names_one_that_raises(tmp_path):
    """The executed path of ``make site`` (the browser tests build from stored outputs)."""
    source = tmp_path / "source"
    source.mkdir()
    _write_notebook(source / "00_tiny.ipynb", nbformat.v4.new_markdown_cell("# Tiny"),
                    nbformat.v4.new_code_cell("print('executed', 6 * 7)"))
    pages = site.build(tmp_path / "site", source, run=True, log=lambda *a: None)
    assert [p.name for p in pages] == ["index.html", "00_tiny.html"]
    assert "executed 42" in pages[1].read_text()  # the output of the run, none was stored
    _write_notebook(source / "01_broken.ipynb",
                    nbformat.v4.new_code_cell("raise ValueError('no such field')"))
    with pytest.raises(RuntimeError, match="01_broken: ValueError no such field"):
        site.build(tmp_path / "site", source, only=["01_broken"], run=True, log=lambda *a: None)
