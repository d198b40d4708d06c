"""The class report: one self-contained HTML page (charts embedded as PNG, no CDN).

It shows how many students and notebooks were graded, per exercise how many of each
status (stacked bars) and the pass rate, the most frequent mistakes (the checks' hints
and the exceptions raised, counted over the class), the distribution of totals per
assignment, and a table of every student's points linking to their feedback page.
Imports: matplotlib (Agg canvas, no pyplot state), the standard library.
"""

from __future__ import annotations

import base64
import html
import io
import re
from collections import Counter, defaultdict
from pathlib import Path

from .feedback import safe_name
from .verdicts import STATUSES, Row, hint_of

COLORS = {"correct": "#2e7d32", "incorrect": "#c62828", "pending": "#9e9e9e", "error": "#ef6c00",
          "timeout": "#6a1b9a", "missing": "#bdbdbd", "tampered": "#000000",
          "wrong-assignment": "#1565c0", "unreadable": "#795548"}


def _png(fig) -> str:
    from matplotlib.backends.backend_agg import FigureCanvasAgg

    FigureCanvasAgg(fig)
    buf = io.BytesIO()
    fig.savefig(buf, format="png", dpi=90, bbox_inches="tight")
    return f'<img alt="chart" src="data:image/png;base64,{base64.b64encode(buf.getvalue()).decode()}">'


def _status_chart(rows: list[Row]) -> str:
    from matplotlib.figure import Figure
    from matplotlib.ticker import MaxNLocator

    labels = list(dict.fromkeys(f"{r.assignment}: {r.exercise}" for r in rows))
    counts = {lab: Counter() for lab in labels}
    for r in rows:
        counts[f"{r.assignment}: {r.exercise}"][r.status] += 1
    fig = Figure(figsize=(8, 0.45 * len(labels) + 1.5))
    ax = fig.add_subplot()
    left = [0] * len(labels)
    for status in STATUSES:
        widths = [counts[lab][status] for lab in labels]
        if any(widths):
            ax.barh(labels, widths, left=left, color=COLORS[status], label=status)
            left = [a + b for a, b in zip(left, widths, strict=True)]
    ax.invert_yaxis()
    ax.xaxis.set_major_locator(MaxNLocator(integer=True))
    ax.set(xlabel="students", title="verdicts per exercise")
    ax.legend(loc="upper center", bbox_to_anchor=(0.5, -0.12), ncol=5, fontsize=8)
    return _png(fig)


def mistakes(rows: list[Row], top: int = 12) -> list[tuple[str, int]]:
    """The most frequent mistakes: hints of failed cases and exceptions, by exercise."""
    counter: Counter = Counter()
    for r in rows:
        seen = set()
        for case in r.details.get("failed_cases", []):
            hint = hint_of(case)
            if hint:
                seen.add(f"{r.exercise}: {hint}")
        if r.status in ("error", "timeout"):
            m = re.search(r"raised (\w+)", r.message)
            what = (f"raised {m.group(1)}" if m else "its cell does not compile" if "compile" in r.message
                    else "did not finish in time" if r.status == "timeout"
                    else "the process crashed or was stopped" if "process" in r.message else r.message[:60])
            seen.add(f"{r.exercise}: {what}")
        counter.update(seen)
    return counter.most_common(top)


def _mistakes_chart(common: list[tuple[str, int]]) -> str:
    from matplotlib.figure import Figure
    from matplotlib.ticker import MaxNLocator

    if not common:
        return "<p>No failed case carried a hint.</p>"
    labels = [m if len(m) < 90 else m[:87] + "…" for m, _ in common]
    fig = Figure(figsize=(9, 0.4 * len(labels) + 1.2))
    ax = fig.add_subplot()
    ax.barh(labels, [n for _, n in common], color=COLORS["incorrect"])
    ax.xaxis.set_major_locator(MaxNLocator(integer=True))
    ax.invert_yaxis()
    ax.tick_params(axis="y", labelsize=7)
    ax.set(xlabel="students", title="most frequent mistakes")
    return _png(fig)


def _totals_chart(totals: dict[str, dict[str, tuple[int, int]]]) -> str:
    from matplotlib.figure import Figure

    names = sorted({a for per in totals.values() for a in per})
    fig = Figure(figsize=(4 * len(names), 3))
    for k, name in enumerate(names, 1):
        ax = fig.add_subplot(1, len(names), k)
        got = [per[name][0] for per in totals.values() if name in per]
        possible = max(per[name][1] for per in totals.values() if name in per)
        ax.hist(got, bins=[x - 0.5 for x in range(possible + 2)], color=COLORS["correct"], rwidth=0.8)
        ax.set(xlabel="points", ylabel="students", title=name)
    return _png(fig)


def write_report(rows: list[Row], path: Path, feedback_dir: Path | None = None) -> Path:
    """Write the class report to ``path`` (HTML) and return it."""
    totals: dict[str, dict[str, tuple[int, int]]] = defaultdict(dict)
    for r in rows:
        got, possible = totals[r.student].get(r.assignment, (0, 0))
        totals[r.student][r.assignment] = (got + r.points, possible + r.possible)
    statuses = Counter(r.status for r in rows)
    per_ex: dict[str, Counter] = defaultdict(Counter)
    for r in rows:
        per_ex[f"{r.assignment}: {r.exercise}"][r.status] += 1
    assignments = list(dict.fromkeys(r.assignment for r in rows))
    e = html.escape
    parts = [
        "<!doctype html><html><head><meta charset='utf-8'><title>Class report</title>",
        "<style>body{font-family:sans-serif;max-width:1000px;margin:2em auto}"
        "table{border-collapse:collapse}td,th{border:1px solid #ccc;padding:3px 8px}</style></head><body>",
        f"<h1>Class report</h1><p>{len(totals)} students, {len(assignments)} assignments, "
        f"{len(rows)} exercise rows: " + ", ".join(f"{n} {e(s)}" for s, n in statuses.most_common()) + "</p>",
        "<h2>Verdicts per exercise</h2>", _status_chart(rows),
        "<table><tr><th>exercise</th><th>pass rate</th>"
        + "".join(f"<th>{e(s)}</th>" for s in STATUSES) + "</tr>",
    ]
    for label, c in per_ex.items():
        total = sum(c.values())
        parts.append(f"<tr><td>{e(label)}</td><td>{100 * c['correct'] / total:.0f}%</td>"
                     + "".join(f"<td>{c[s] or ''}</td>" for s in STATUSES) + "</tr>")
    parts += ["</table><h2>Most frequent mistakes</h2>", _mistakes_chart(mistakes(rows)),
              "<h2>Totals</h2>", _totals_chart(totals),
              "<table><tr><th>student</th>" + "".join(f"<th>{e(a)}</th>" for a in assignments) + "</tr>"]
    for student, per in sorted(totals.items()):
        link = e(student)
        if feedback_dir is not None:
            target = Path(feedback_dir).resolve() / f"{safe_name(student)}.md"
            link = f"<a href='{e(target.as_uri())}'>{e(student)}</a>"
        cells = "".join(f"<td>{per[a][0]} / {per[a][1]}</td>" if a in per else "<td></td>"
                        for a in assignments)
        parts.append(f"<tr><td>{link}</td>{cells}</tr>")
    parts.append("</table></body></html>")
    path.parent.mkdir(parents=True, exist_ok=True)
    path.write_text("\n".join(parts), encoding="utf-8")
    return path
