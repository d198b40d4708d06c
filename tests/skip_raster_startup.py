"""IPython startup file for test passes that run a notebook without drawing its pixels.

Copied into the test session's IPYTHONDIR by ``tests/nbval_rerun.py``; it acts only in
kernels started with ``COURSE_KIT_SKIP_RASTER=1`` (``--nbval-skip-raster=DIR``). Every PNG
that matplotlib would rasterize (inline figures, player and animation frames) becomes a
1 x 1 white PNG; the notebook's code, its numbers and every text output run as usual, and
nbval never compares PNG data. Rasterizing is a third of a notebook's running time, and the
first strict pass of ``make test`` (and the browser stage) still draws every figure.
"""

import os

_draw_artists = __name__ == "course_kit_rerun"
if os.environ.get("COURSE_KIT_SKIP_RASTER") == "1" or _draw_artists:
    import io as _io

    import matplotlib.backend_bases as _backend_bases
    from PIL import Image as _Image

    _buffer = _io.BytesIO()
    _Image.new("RGB", (1, 1), "white").save(_buffer, format="PNG")
    _BLANK_PNG = _buffer.getvalue()
    _draw = _backend_bases.FigureCanvasBase.print_figure

    def _print_figure(self, filename, *args, **kwargs):
        fmt = kwargs.get("format") or (
            os.path.splitext(filename)[1][1:] if isinstance(filename, (str, os.PathLike)) else "")
        if str(fmt).lower() != "png":
            return _draw(self, filename, *args, **kwargs)
        if _draw_artists:
            self.figure.draw_without_rendering()
        if hasattr(filename, "write"):
            filename.write(_BLANK_PNG)
        else:
            with open(filename, "wb") as out:
                out.write(_BLANK_PNG)
        return None

    _backend_bases.FigureCanvasBase.print_figure = _print_figure

    # Kernel-free players draw their frames straight from the canvas (blitting), not through
    # print_figure: in this pass they take the savefig path, whose PNGs are blanked above.
    import course_lib.players as _players

    _players._draw_frames = _players._save_in_full

