"""The passes of ``make test`` that skip rasterizing (tests/skip_raster_startup.py).

The startup file must change nothing unless asked, must turn only PNG output into a blank
pixel (a player still builds from such frames), and the Makefile must keep one strict pass
of the solutions that draws every figure.
"""

import os
import re
import subprocess
import sys

from notebook_helpers import ROOT

STARTUP = ROOT / "tests" / "skip_raster_startup.py"
PROBE = f"""
import io, runpy
import matplotlib
matplotlib.use("Agg")
import matplotlib.pyplot as plt
runpy.run_path({str(STARTUP)!r})
from course_lib.players import _png_size, animation_player
from matplotlib.animation import FuncAnimation
fig, ax = plt.subplots(figsize=(4, 3), dpi=50)
line, = ax.plot([0, 1], [0, 1])
png, svg = io.BytesIO(), io.BytesIO()
fig.savefig(png, format="png", bbox_inches="tight")
fig.savefig(svg, format="svg")
anim = FuncAnimation(fig, lambda i: line.set_ydata([0, i]), frames=3)
player = animation_player(anim)
import course_lib.players as P
print(_png_size(png.getvalue()), b"<svg" in svg.getvalue(), len(player.labels),
      P._draw_frames is P._save_in_full)
"""


def probe(flag: str) -> str:
    env = {**os.environ, "COURSE_KIT_SKIP_RASTER": flag}
    out = subprocess.run([sys.executable, "-c", PROBE], env=env, capture_output=True, text=True,
                         timeout=120, check=True)
    return out.stdout.strip()


def test_png_becomes_one_pixel_only_when_asked_and_other_formats_still_draw():
    assert probe("1") == "(1, 1) True 3 True"       # players take the blanked savefig path
    size = re.match(r"\((\d+), (\d+)\) True 3 False$", probe("0"))
    assert size and int(size[1]) > 50 and int(size[2]) > 50  # a real drawing


def test_one_strict_pass_of_the_solutions_still_draws_every_figure():
    make = (ROOT / "Makefile").read_text()
    nbval = re.search(r"^test-nbval:.*?(?=^\S)", make, re.S | re.M)[0]
    rounding = re.search(r"^test-rounding:.*?(?=^\S)", make, re.S | re.M)[0]
    assert "--nbval-skip-raster" not in nbval and nbval.rstrip().endswith("solutions")  # draws
    # the second rounding blanks the PNGs of the notebooks it runs (the paired ones)
    assert "--nbval-skip-raster=$(PAIRED)" in rounding and rounding.rstrip().endswith("$(PAIRED)")


def test_the_reruns_mode_blanks_pngs_but_draws_the_artists():
    """``run_name="course_kit_rerun"`` (tests/nbval_rerun.py, before the re-runs in other
    orders): a PNG is one pixel, yet a figure whose artists cannot draw still raises."""
    code = f"""
import io, runpy
import matplotlib
matplotlib.use("Agg")
import matplotlib.pyplot as plt
runpy.run_path({str(STARTUP)!r}, run_name="course_kit_rerun")
from course_lib.players import _png_size
fig, ax = plt.subplots(figsize=(4, 3), dpi=50)
line, = ax.plot([0, 1], [0, 1])
png = io.BytesIO()
fig.savefig(png, format="png")
line.set_xdata([0, 1, 2])
try:
    fig.savefig(io.BytesIO(), format="png")
    raised = None
except ValueError as exc:
    raised = "shape mismatch" in str(exc)
print(_png_size(png.getvalue()), raised)
"""
    env = {**os.environ, "COURSE_KIT_SKIP_RASTER": "0"}
    out = subprocess.run([sys.executable, "-c", code], env=env, capture_output=True, text=True,
                         timeout=120, check=True).stdout.strip()
    assert out == "(1, 1) True"
