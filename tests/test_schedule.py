"""tests/schedule.py hands the costliest files to pytest-xdist first, keeping each file's
items together and in order."""

from pathlib import Path
from types import SimpleNamespace

import schedule
from notebook_helpers import ROOT


def test_every_listed_file_exists_once():
    stems = {p.stem for p in (ROOT / "tests").glob("test_*.py")}
    stems |= {p.stem for p in (ROOT / "solutions").glob("*.ipynb")}
    assert len(set(schedule.HEAVIEST)) == len(schedule.HEAVIEST)
    assert set(schedule.HEAVIEST) <= stems, set(schedule.HEAVIEST) - stems


def test_heaviest_first_and_each_file_keeps_its_order():
    names = ["tests/test_a.py", "solutions/02_forward_euler.ipynb", "tests/test_a.py",
             "tests/test_grading_corpus.py", "build/paired/02_forward_euler.ipynb",
             "tests/test_b.py", "tests/test_grading_corpus.py"]
    items = [SimpleNamespace(path=Path(n), n=k) for k, n in enumerate(names)]
    schedule.pytest_collection_modifyitems(None, None, items)
    assert [(str(i.path), i.n) for i in items] == [
        ("tests/test_grading_corpus.py", 3), ("tests/test_grading_corpus.py", 6),
        ("solutions/02_forward_euler.ipynb", 1), ("build/paired/02_forward_euler.ipynb", 4),
        ("tests/test_a.py", 0), ("tests/test_a.py", 2), ("tests/test_b.py", 5)]


def test_make_test_keeps_the_collection_order():
    make = (ROOT / "Makefile").read_text()
    assert "XDIST  := -n $(JOBS) --dist loadfile --no-loadscope-reorder" in make
