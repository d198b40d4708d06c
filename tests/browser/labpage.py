"""Driving a notebook in JupyterLab from Playwright, through ``window.jupyterapp``.

JupyterLab is started with ``--LabApp.expose_app_in_browser=True``; we wait for the
notebook's session to have a connected, idle kernel (the execution indicator reads idle
before a kernel is attached, so it cannot be trusted), run cells through JupyterLab's own
commands, read outputs from the notebook model (off-screen cells may not be in the DOM:
JupyterLab renders them lazily), and ask the kernel what a widget computed.
"""

from __future__ import annotations

import json
import time

NB = "window.jupyterapp.shell.currentWidget"

# the current widget is the notebook at ``path`` (the argument), its model loaded
_OPEN = f"""const w = window.jupyterapp && {NB};
  if (!w || !w.context || w.context.path !== path || !w.context.isReady
      || w.content.widgets.length === 0) return false;"""

READY = f"""(path) => {{
  {_OPEN}
  const k = w.sessionContext && w.sessionContext.session && w.sessionContext.session.kernel;
  return !!k && k.connectionStatus === 'connected' && k.status === 'idle';
}}"""

#: the notebook's model is loaded and its session exists (its kernel may still be starting)
LOADED = f"""(path) => {{
  {_OPEN}
  return !!(w.sessionContext && w.sessionContext.session);
}}"""

#: the notebook's model is loaded (opened with no kernel)
MODEL = f"""(path) => {{
  {_OPEN}
  return true;
}}"""


def _path(page) -> str:
    return page.evaluate(f"() => {NB}.context.path")


def open_notebook(page, lab, path: str, *, kernel: bool = True) -> None:
    """Open ``path`` (relative to the served folder) and wait for an idle kernel. With
    ``kernel=False`` (a test of stored outputs only, which no kernel changes) the notebook
    opens in the worker's JupyterLab window with no kernel (JupyterLab's own
    ``kernelPreference: {shouldStart: false}``; starting one costs 9 to 13 s here), or, in a
    fresh page, with its kernel left starting, unwaited for, once the session exists (so that
    ``lab.shutdown_kernels()`` stops it). In a page where JupyterLab runs already, the
    notebook is opened with JupyterLab's docmanager:open command."""
    if page.url.startswith(lab.base) and page.evaluate("() => !!window.jupyterapp"):
        # the command resolves to the notebook panel: returned, Playwright would serialize
        # its whole object graph (outputs of a megabyte included), 3 to 6 s per notebook
        page.evaluate("""async ([path, start]) => {
            await window.jupyterapp.commands.execute('docmanager:open', {path, factory: 'Notebook',
                ...(start ? {} : {kernelPreference: {shouldStart: false}})}); }""", [path, kernel])
        wait = READY if kernel else MODEL
    else:
        page.goto(lab.url(path))
        wait = READY if kernel else LOADED
    page.wait_for_function(wait, arg=path, timeout=120_000, polling=100)


def is_dirty(page) -> bool:
    """Whether the notebook is modified, asked once the notebook has taken the kernel's
    spec and language_info into its metadata (JupyterLab does it just after the kernel
    connects; a stored notebook that differs turns 'modified' then)."""
    return page.evaluate(f"""async () => {{
        const w = {NB};
        const k = w.sessionContext.session.kernel;
        await Promise.all([k.info, k.spec]);
        await new Promise(r => setTimeout(r, 200));  // the panel's own handlers of them
        return w.context.model.dirty;
      }}""")


def _run(page, index: int, command: str, timeout_ms: int) -> None:
    """Make cell ``index`` active, run JupyterLab's ``command`` and wait for the kernel."""
    page.evaluate(f"""async ([i, command]) => {{
        const w = {NB};
        w.content.activeCellIndex = i;
        await window.jupyterapp.commands.execute(command);
      }}""", [index, command])
    page.wait_for_function(READY, arg=_path(page), timeout=timeout_ms, polling=100)


def rerun(page, index: int) -> None:
    """Run cell ``index`` again (as a student does, out of order) and wait for the kernel."""
    _run(page, index, "notebook:run-cell", 120_000)


def run_above(page, index: int) -> None:
    """Run every cell above cell ``index`` (JupyterLab's Run All Above) and wait."""
    _run(page, index, "notebook:run-all-above", 300_000)


def outputs_of(page, index: int) -> list[str]:
    """The output types (and mime types) of cell ``index``."""
    return page.evaluate(f"""(i) => {{
        const outs = {NB}.content.widgets[i].model.outputs;
        return Array.from({{length: outs.length}}, (_, j) => {{
          const o = outs.get(j); return o.type + ':' + Object.keys(o.data || {{}}).join(',');
        }});
      }}""", index)


def problems(page) -> list[str]:
    """Error outputs and stderr text of every code cell (from the model, not the DOM)."""
    return page.evaluate(f"""() => {{
      const found = [];
      {NB}.content.widgets.forEach((c, i) => {{
        if (c.model.type !== 'code') return;
        const outs = c.model.outputs;
        for (let j = 0; j < outs.length; j++) {{
          const o = outs.get(j).toJSON();
          if (o.output_type === 'error') found.push(`cell ${{i}}: ${{o.ename}}: ${{o.evalue}}`);
          if (o.output_type === 'stream' && o.name === 'stderr')
            found.push(`cell ${{i}} (stderr): ${{String(o.text).slice(0, 300)}}`);
        }}
      }});
      return found;
    }}""")


def find_cell(page, needle: str, *, widget: bool = False) -> int:
    """Index of the first code cell whose source contains ``needle`` (and, with
    ``widget=True``, whose outputs hold a live widget)."""
    index = page.evaluate(f"""([needle, widget]) => {NB}.content.widgets.findIndex(c => {{
        if (c.model.type !== 'code' || !c.model.sharedModel.source.includes(needle)) return false;
        if (!widget) return true;
        const outs = c.model.outputs;
        for (let j = 0; j < outs.length; j++)
          if ('application/vnd.jupyter.widget-view+json' in (outs.get(j).data || {{}})) return true;
        return false;
      }})""", [needle, widget])
    assert index >= 0, f"no code cell containing {needle!r}" + (" with a widget" if widget else "")
    return index


def cell(page, index: int):
    """Scroll cell ``index`` into view (rendering it) and return a locator for its node."""
    page.evaluate(f"""async (i) => {{
        const nb = {NB}.content;
        await nb.scrollToItem(i, 'start');
        nb.widgets[i].node.setAttribute('data-test-cell', String(i));
      }}""", index)
    loc = page.locator(f'[data-test-cell="{index}"]')
    loc.wait_for(state="attached")
    return loc


def kernel_run(page, code: str) -> str:
    """Run ``code`` in the notebook's kernel (no cell, no history); return its stdout."""
    return page.evaluate(f"""async (code) => {{
        const k = {NB}.sessionContext.session.kernel;
        let out = '';
        const f = k.requestExecute({{code, store_history: false}});
        f.onIOPub = (m) => {{
          if (m.header.msg_type === 'stream') out += m.content.text;
          if (m.header.msg_type === 'error') out += 'ERROR ' + m.content.ename + ': ' + m.content.evalue;
        }};
        await f.done;
        return out;
      }}""", code)


VERDICTS = """
import gc, json
from course_lib.widgets import ExplorerView
def _verdict(r):
    v = getattr(r, "verdict", None)
    if isinstance(v, str):
        return v.split(":")[0].strip().lower()
    if hasattr(r, "reversal"):  # a flock: unstable when headings flip between steps
        return "stable" if r.reversal > 0.5 else "unstable"
    return "stable" if getattr(r, "stable", True) else "unstable"
print(json.dumps([[v.controls[NAME].value, _verdict(v.result)] for v in gc.get_objects()
                  if isinstance(v, ExplorerView) and NAME in v.controls]))
"""


def verdict(page, control: str, value: float) -> str:
    """The verdict of the live view whose ``control`` is at ``value`` ("stable"/"unstable")."""
    out = kernel_run(page, f"NAME = {control!r}" + VERDICTS)
    views = json.loads(out)
    close = [v for x, v in views if abs(x - value) <= 1e-3 * abs(value)]
    assert close, f"no view with {control} = {value}: {views}"
    return close[-1]


def set_slider(page, scope, label: str, value: float) -> None:
    """Type ``value`` into the readout of the slider labelled ``label`` and press Enter."""
    slider = scope.locator(".widget-slider").filter(
        has=page.locator(".widget-label", has_text=label)).first
    readout = slider.locator(".widget-readout")
    readout.click()
    page.keyboard.press("Control+A")
    page.keyboard.type(f"{value:g}")
    page.keyboard.press("Enter")


def picture(scope) -> str:
    """``src`` of the widget's picture (the largest image inside the widget)."""
    return scope.evaluate("""(root) => {
        const imgs = Array.from(root.querySelectorAll('.jupyter-widgets img'));
        imgs.sort((a, b) => b.width * b.height - a.width * a.height);
        return imgs.length ? imgs[0].src : '';
      }""")


def wait_new_picture(scope, old: str, timeout: float = 90) -> str:
    deadline = time.monotonic() + timeout
    while time.monotonic() < deadline:
        src = picture(scope)
        if src and src != old:
            return src
        time.sleep(0.2)
    raise AssertionError("the widget's picture did not change")
