"""`make present`: the lecture notebook holds the demos and just the cells they need, runs
in a kernel, and Voila is started on 127.0.0.1 with a token. (Voila itself is driven in
tests/browser/test_browser_voila.py.)"""

import nbformat
import pytest
from notebook_helpers import ROOT

from course_lib.instructor import present

WIDGET = "application/vnd.jupyter.widget-view+json"
WIDGET_NOTEBOOKS = ["03_stability", "06_forces", "07_springs", "08_hair_chains"]


def _solution(name: str) -> nbformat.NotebookNode:
    return nbformat.read(ROOT / "solutions" / f"{name}.ipynb", as_version=4)


@pytest.mark.parametrize("name", WIDGET_NOTEBOOKS)
def test_lecture_notebook_is_the_title_the_demos_and_hidden_support(name):
    nb = _solution(name)
    demos = present.demo_indices(nb)
    assert demos and all(any(WIDGET in o.get("data", {}) for o in nb.cells[i].outputs)
                         for i in demos)
    lecture = present.lecture_notebook(nb)
    assert lecture.cells[0].cell_type == "markdown" and lecture.cells[0].source.startswith("# ")
    shown = [c for c in lecture.cells if c.cell_type == "code"
             and not c.source.startswith("%%capture")]
    assert [c.source for c in shown] == [nb.cells[i].source for i in demos]
    support = [c for c in lecture.cells if c.source.startswith("%%capture")]
    assert support and "import" in support[0].source  # at least the imports cell
    assert len(lecture.cells) < len(nb.cells) / 2


def test_lecture_notebook_runs_and_shows_only_the_widget():
    from nbclient import NotebookClient

    lecture = present.lecture_notebook(_solution("03_stability"))
    NotebookClient(lecture, timeout=120, kernel_name="python3",
                   resources={"metadata": {"path": str(ROOT / "solutions")}}).execute()
    outputs = [o for c in lecture.cells if c.cell_type == "code" for o in c.outputs]
    assert outputs and all(WIDGET in o.get("data", {}) for o in outputs), outputs


def test_needed_cells_are_found_by_name():
    cells = ["import numpy as np\n%matplotlib inline", "a = np.arange(3)", "b = 2",
             "def f(x):\n    return a * x", "unused = 1", "f(b)"]
    nb = nbformat.v4.new_notebook(cells=[nbformat.v4.new_code_cell(s) for s in cells])
    nb.cells[5].metadata["tags"] = ["demo"]
    assert present.demo_indices(nb) == [5]
    assert present.support_indices(nb, [5]) == [0, 1, 2, 3]
    used, bound = present.names_used_and_defined("%time y = len(x)")
    assert used == {"x"} and bound == {"y"}


def test_bad_requests_say_what_to_do(tmp_path, capsys):
    with pytest.raises(ValueError, match="no demo"):
        present.lecture_notebook(nbformat.v4.new_notebook(cells=[nbformat.v4.new_code_cell("1")]))
    with pytest.raises(ValueError, match="03_stability"):
        present.find_notebook("99", ROOT / "solutions")
    assert present.main([]) == 2
    assert "make present NB=03_stability" in capsys.readouterr().err


def test_voila_listens_on_localhost_with_a_token():
    cmd = present.voila_command(ROOT / "x.ipynb", 8123, "secret")
    assert "--Voila.ip=127.0.0.1" in cmd and "--token=secret" in cmd and "--no-browser" in cmd
    env = present.voila_env()
    assert env["JUPYTER_CONFIG_PATH"].split(":")[0] == str(ROOT / "jupyter_config")
    # the course's page template: Voila's lab page without its CDN links
    assert "--template=course" in cmd
    assert env["JUPYTER_PATH"].split(":")[0] == str(ROOT / "jupyter_data")
    page = (ROOT / "jupyter_data" / "voila" / "templates" / "course" / "index.html.j2").read_text()
    assert "extends 'lab/index.html.j2'" in page and "fontawesome-free@^5/css/all.min.css" in page
    assert (ROOT / "jupyter_config" / "voila.py").exists()
