"""Static parts of the kernel-free player (:mod:`course_lib.players`): CSS, script, controls.

No network: the icons are inline SVG paths, the script plain ES5-style JavaScript with no
library. The script finds its player from its own ``<script>`` element (or, failing that,
the player's id), so it works wherever the HTML lands: a JupyterLab output rendered late by
the notebook's lazy windowing, a Voila page, a static site. It writes the controls, so
where scripts do not run (an untrusted notebook) the reader sees the first frame and a hint
rather than dead buttons; it marks the player ``data-ready`` and, while it plays,
``data-playing``; the current frame is ``data-frame`` (browser tests read these). A press
on the controls drives the player only: it does not reach JupyterLab, whose notebook would
also select the cell (and focus it, which may scroll the page under the pointer). Imports
nothing.
"""

from __future__ import annotations

_ICONS = {
    "first": "M2 2h2v12H2zM9 2v12L4 8zM15 2v12L9 8z",
    "prev": "M3 2h2v12H3zM13 2v12L5 8z",
    "play": "M4 2v12l10-6z",
    "pause": "M3 2h4v12H3zM9 2h4v12H9z",
    "next": "M11 2h2v12h-2zM3 2v12l8-6z",
    "last": "M12 2h2v12h-2zM7 2v12l5-6zM1 2v12l6-6z",
}
_TITLES = {"first": "first frame", "prev": "previous frame", "play": "play / pause",
           "next": "next frame", "last": "last frame"}


def _svg(name: str) -> str:
    return (f'<svg viewBox="0 0 16 16" width="14" height="14" aria-hidden="true">'
            f'<path d="{_ICONS[name]}"/></svg>')


def controls_html(kind: str, n: int, label: str, mode: str) -> str:
    """The control bar: step buttons (and play/pause and a mode menu for animations), the
    slider over ``n`` frames and the label of the first frame (already HTML-escaped)."""
    acts = ["first", "prev", "play", "next", "last"] if kind == "animation" else ["prev", "next"]
    buttons = "".join(
        f'<button type="button" class="clp-btn" data-act="{a}" title="{_TITLES[a]}" '
        f'aria-label="{_TITLES[a]}">{_svg(a)}</button>' for a in acts)
    slider = (f'<input type="range" class="clp-slider" min="0" max="{n - 1}" step="1" '
              f'value="0" aria-label="frame">')
    menu = ""
    if kind == "animation":
        options = "".join(f'<option value="{m}"{" selected" if m == mode else ""}>{m}</option>'
                          for m in ("loop", "once", "reflect"))
        menu = f'<select class="clp-mode" aria-label="at the end">{options}</select>'
    return (f'<div class="clp-bar">{buttons}{slider}<span class="clp-label">{label}</span>'
            f'{menu}</div>\n')


PLAYER_CSS = (
    ".clp{font:13px/1.4 system-ui,-apple-system,'Segoe UI',Roboto,sans-serif;margin:4px 0;"
    "max-width:100%;color:#222}"
    ".clp-img{display:block;max-width:100%;height:auto;background:#fff}"
    ".clp-title{font-weight:600;margin:0 0 2px}"
    ".clp-caption{min-height:1.4em;margin:2px 0;white-space:pre-wrap}"
    ".clp-bar{display:flex;align-items:center;gap:4px;flex-wrap:wrap;max-width:800px}"
    ".clp-btn{display:inline-flex;align-items:center;justify-content:center;width:30px;"
    "height:26px;padding:0;border:1px solid #aaa;border-radius:3px;background:#f4f4f4;"
    "color:#222;cursor:pointer}"
    ".clp-btn:hover{background:#e2e2e2}.clp-btn svg{fill:currentColor}"
    ".clp-slider{flex:1 1 160px;min-width:120px}"
    ".clp-label{min-width:8em;font-variant-numeric:tabular-nums}"
    ".clp-mode{font:inherit}"
    ".clp-hint{color:#666;font-size:12px}.clp[data-ready] .clp-hint{display:none}"
)

_PLAY_SVG = _svg("play").replace('"', '\\"')
_PAUSE_SVG = _svg("pause").replace('"', '\\"')

PLAYER_JS = """(function () {
  var s = document.currentScript;
  var root = (s && s.closest && s.closest('.clp')) || document.getElementById('__UID__');
  if (!root || root.getAttribute('data-ready')) { return; }
  var d = JSON.parse(root.querySelector('.clp-data').textContent);
  var hint = root.querySelector('.clp-hint');
  hint.insertAdjacentHTML('beforebegin', d.controls);
  hint.parentNode.removeChild(hint);
  var img = root.querySelector('.clp-img'), cap = root.querySelector('.clp-caption');
  var lab = root.querySelector('.clp-label'), sl = root.querySelector('.clp-slider');
  var menu = root.querySelector('.clp-mode'), btn = root.querySelector('[data-act=play]');
  var first = img.getAttribute('src'), n = d.frames.length, k = 0, dir = 1, timer = null;
  function show(j) {
    k = Math.max(0, Math.min(n - 1, j));
    img.src = k === 0 ? first : 'data:image/png;base64,' + d.frames[k];
    sl.value = k;
    lab.textContent = d.labels[k];
    cap.textContent = d.captions[k];
    root.setAttribute('data-frame', k);
  }
  function stop() {
    if (timer !== null) { clearInterval(timer); timer = null; }
    root.removeAttribute('data-playing');
    if (btn) { btn.innerHTML = "__PLAY__"; }
  }
  function mode() { return menu ? menu.value : d.mode; }
  function tick() {
    if (!root.isConnected) { stop(); return; }
    var j = k + dir;
    if (j >= n || j < 0) {
      if (mode() === 'loop') { j = dir > 0 ? 0 : n - 1; }
      else if (mode() === 'reflect') { dir = -dir; j = k + dir; }
      else { stop(); return; }
    }
    show(j);
  }
  function start() {
    if (timer !== null || n < 2) { return; }
    if (k === n - 1 && mode() === 'once') { show(0); }
    timer = setInterval(tick, d.interval);
    root.setAttribute('data-playing', '1');
    if (btn) { btn.innerHTML = "__PAUSE__"; }
  }
  root.addEventListener('click', function (e) {
    var b = e.target.closest ? e.target.closest('[data-act]') : null;
    if (!b || !root.contains(b)) { return; }
    var a = b.getAttribute('data-act');
    if (a === 'play') { if (timer === null) { start(); } else { stop(); } return; }
    stop();
    show(a === 'first' ? 0 : a === 'last' ? n - 1 : a === 'prev' ? k - 1 : k + 1);
  });
  sl.addEventListener('input', function () { stop(); show(+sl.value); });
  // A press on the controls is the player's: JupyterLab's notebook would also select and
  // focus the cell, which may scroll the page while the button is being pressed.
  var bar = root.querySelector('.clp-bar');
  ['mousedown', 'pointerdown'].forEach(function (t) {
    bar.addEventListener(t, function (e) { e.stopPropagation(); });
  });
  root.setAttribute('data-frame', 0);
  root.setAttribute('data-ready', '1');
})();""".replace("__PLAY__", _PLAY_SVG).replace("__PAUSE__", _PAUSE_SVG)
