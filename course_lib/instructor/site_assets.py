"""Vendored JavaScript and fonts for the static site: installed by npm, copied into ``_static``.

``vendor/package.json`` and ``vendor/package-lock.json`` (committed) pin the npm
packages the pages need; :func:`install` runs ``npm ci`` into ``vendor/node_modules``
(git-ignored) when it is missing or older than the lock, and :func:`copy_assets` copies
the files a page loads into the site's ``_static`` folder:

- ``require.js`` (npm ``requirejs``): the AMD loader the widget manager needs;
- ``html-manager/embed-amd.js`` and its fonts (npm ``@jupyter-widgets/html-manager``):
  renders saved widget state;
- ``mathjax/tex-chtml-full.js`` and its fonts (npm ``mathjax`` 3): renders the math;
- ``sre/``: what MathJax's accessibility features (speech, Braille, the explorer) load once a
  reader turns them on: the Speech Rule Engine's locale maps, which the ``mathjax`` package
  ships in ``es5/sre/mathmaps`` (copied as JSON, and as small scripts ``sre/maps/<locale>.js``
  because a page opened from disk may not fetch JSON: Chromium refuses XHR on ``file://``),
  and ``wgxpath.install.js`` (npm ``wicked-good-xpath``, for browsers without XPath). Left to
  its defaults the engine would fetch both from a CDN; :data:`SRE_FEATURE_JS`, run before
  MathJax, points it at these copies.

Nothing is fetched when a page is viewed. Imports only the standard library.
"""

from __future__ import annotations

import json
import shutil
import subprocess
from pathlib import Path

#: Where package.json, package-lock.json and node_modules live.
VENDOR = Path(__file__).resolve().parents[2] / "vendor"

#: Site-relative URLs of the assets, for the page templates.
REQUIRE_JS = "_static/require.js"
WIDGETS_JS = "_static/html-manager/embed-amd.js"
MATHJAX_JS = "_static/mathjax/tex-chtml-full.js"

# MathJax: the combined TeX + CommonHTML component and what it may load at run time.
_MATHJAX_PARTS = ("tex-chtml-full.js", "output/chtml/fonts/woff-v2", "ui", "a11y",
                  "input/tex/extensions", "input/mml.js", "input/mml", "adaptors", "sre")

#: Run before MathJax loads: the Speech Rule Engine reads ``window.SREfeature`` for where its
#: locale maps (``json``) and XPath polyfill (``xpath``) live, and for a ``custom`` loader.
#: MathJax's a11y/sre component replaces that object and sets its own loader (a fetch of the
#: JSON), so the object is kept behind an accessor: our paths always win, and from ``file://``
#: a locale is read from its script wrapper instead of fetched.
SRE_FEATURE_JS = r"""(function () {
  var base = new URL('_static/sre/', document.baseURI).href, feature;
  function fromScript(locale) {
    return new Promise(function (ok, fail) {
      var maps = window.courseSreMaps || {};
      if (maps[locale]) { ok(maps[locale]); return; }
      var tag = document.createElement('script');
      tag.src = base + 'maps/' + locale + '.js';
      tag.onload = function () {
        var m = (window.courseSreMaps || {})[locale];
        if (m) { ok(m); } else { fail(new Error('no speech maps for ' + locale)); }
      };
      tag.onerror = function () { fail(new Error('no speech maps for ' + locale)); };
      document.head.appendChild(tag);
    });
  }
  function make(given) {
    var theirs = given && given.custom, out = {};
    for (var k in given || {}) { if (k !== 'custom') { out[k] = given[k]; } }
    out.json = base + 'mathmaps';
    out.xpath = base + 'wgxpath.install.js';
    Object.defineProperty(out, 'custom', {enumerable: true, configurable: true,
      get: function () {
        return function (locale) {
          return (location.protocol === 'file:' || !theirs) ? fromScript(locale) : theirs(locale);
        };
      },
      set: function (fn) { theirs = fn; }});
    return out;
  }
  feature = make({});
  Object.defineProperty(window, 'SREfeature', {configurable: true,
    get: function () { return feature; }, set: function (v) { feature = make(v); }});
})();"""


class AssetError(RuntimeError):
    """npm is missing or the vendored packages could not be installed."""


def _installed(vendor: Path) -> bool:
    marker = vendor / "node_modules" / ".package-lock.json"
    lock = vendor / "package-lock.json"
    return marker.exists() and marker.stat().st_mtime >= lock.stat().st_mtime


def install(vendor: Path = VENDOR, *, quiet: bool = True) -> Path:
    """Run ``npm ci`` in ``vendor`` unless ``node_modules`` is already up to date.

    Returns the ``node_modules`` folder. Raises :class:`AssetError` (saying what to do)
    when npm is not installed or fails.
    """
    vendor = Path(vendor)
    if not (vendor / "package-lock.json").exists():
        raise AssetError(f"{vendor}/package-lock.json is missing: it pins the site's npm assets")
    if _installed(vendor):
        return vendor / "node_modules"
    npm = shutil.which("npm")
    if npm is None:
        raise AssetError("npm is needed once to vendor the site's JavaScript and fonts "
                         "(MathJax, require.js, the widget manager): install Node.js with npm")
    cmd = [npm, "ci", "--ignore-scripts", "--no-audit", "--no-fund"]
    if quiet:
        cmd.append("--loglevel=error")
    done = subprocess.run(cmd, cwd=vendor, capture_output=True, text=True)
    if done.returncode != 0:
        raise AssetError(f"`npm ci` failed in {vendor}:\n{done.stdout}\n{done.stderr}")
    return vendor / "node_modules"


def _copy(src: Path, dst: Path) -> None:
    if src.is_dir():
        shutil.copytree(src, dst, dirs_exist_ok=True,
                        ignore=shutil.ignore_patterns("*.map", "*.LICENSE.txt"))
    else:
        dst.parent.mkdir(parents=True, exist_ok=True)
        shutil.copy2(src, dst)


def copy_assets(static: Path, vendor: Path = VENDOR) -> list[Path]:
    """Install (if needed) and copy every asset into ``static``; return the top entries."""
    modules = install(vendor)
    static = Path(static)
    static.mkdir(parents=True, exist_ok=True)
    _copy(modules / "requirejs" / "require.js", static / "require.js")
    manager = modules / "@jupyter-widgets" / "html-manager" / "dist"
    (static / "html-manager").mkdir(exist_ok=True)
    for f in manager.iterdir():
        # embed-amd.js loads its fonts from its own folder; the other bundles are unused
        if (f.is_file() and f.suffix in {".woff", ".woff2", ".ttf", ".eot", ".svg"}) or \
                f.name == "embed-amd.js":
            _copy(f, static / "html-manager" / f.name)
    mathjax = modules / "mathjax" / "es5"
    for part in _MATHJAX_PARTS:
        _copy(mathjax / part, static / "mathjax" / part)
    sre = static / "sre"
    _copy(mathjax / "sre" / "mathmaps", sre / "mathmaps")
    (sre / "maps").mkdir(parents=True, exist_ok=True)
    for path in sorted((mathjax / "sre" / "mathmaps").glob("*.json")):
        text = json.dumps(path.read_text(encoding="utf-8"))
        (sre / "maps" / f"{path.stem}.js").write_text(
            f"(window.courseSreMaps = window.courseSreMaps || {{}})[{json.dumps(path.stem)}] = {text};\n",
            encoding="utf-8")
    _copy(modules / "wicked-good-xpath" / "dist" / "wgxpath.install.js", sre / "wgxpath.install.js")
    return [static / "require.js", static / "html-manager", static / "mathjax", sre]
