"""Speed against accuracy: a Markdown table, a log-log chart of cost against error, and the
cheapest setting within a tolerance of the finest run on every headline metric.

    cd scripts && /usr/bin/python3 -m sweep report OUTPUT [--markdown X.md] [--png X.png] [--tolerance 0.05]
"""
from __future__ import annotations

from pathlib import Path

from . import metrics as metrics_module
from . import scenes

SHOWN = [  # (metric, column title, scale, digits)
    ("peak_velocity", "peak v (m/s)", 1.0, 3),
    ("peak_flow", "peak Q (cm²/s)", 1e4, 1),
    ("pspd_mmHg", "PSPD (mmHg)", 1.0, 2),
    ("opening_start", "opening start (ms)", 1e3, 1),
    ("rvot", "RVOT (ms)", 1e3, 1),
    ("eoa", "EOA", 1.0, 3),
    ("rvct", "RVCT (ms)", 1e3, 1),
    ("diastolic_force", "diastolic F", 1.0, 2),
    ("peak_strain", "peak strain", 1.0, 3),
    ("peak_stress", "peak stress (MPa)", 1e-6, 2),
    ("max_edge_speed", "max edge speed (m/s)", 1.0, 1),   # shown, not a headline metric
]


def choose_finest(results: list[dict], label: str | None) -> dict | None:
    if label is not None:
        for r in results:
            if r["label"] == label:
                return r
        return None
    done = [r for r in results if usable(r)]
    return max(done, key=lambda r: r["cost"]["cpu_s"]) if done else None


REACHED_END = ("completed", "leaks", "energy growth")


def usable(result: dict) -> bool:
    """A run whose metrics count: it reached its end. Leaks and energy growth (a fluttering
    free edge, a force spike) do not stop a run; they are shown beside its errors."""
    return result["outcome"]["kind"] in REACHED_END


def with_errors(results: list[dict], finest: dict | None) -> list[dict]:
    rows = []
    for r in results:
        errors = metrics_module.errors_against(r["metrics"], finest["metrics"]) if finest and usable(r) else {}
        rows.append({**r, "errors": errors,
                     "max_error": max((abs(e) for e in errors.values()), default=None)})
    return rows


def cheapest_within(rows: list[dict], finest: dict | None, tolerance: float) -> dict | None:
    """The usable run of least CPU time whose every headline metric that the finest run has is
    within `tolerance` (relative) of the finest's."""
    if finest is None:
        return None
    needed = [m for m in metrics_module.HEADLINE if finest["metrics"].get(m) is not None]
    good = [r for r in rows if usable(r) and r["label"] != finest["label"]
            and all(m in r["errors"] and abs(r["errors"][m]) <= tolerance for m in needed)]
    return min(good, key=lambda r: r["cost"]["cpu_s"]) if good else None


def _fmt(value, scale=1.0, digits=2) -> str:
    if value is None:
        return "–"
    return f"{value * scale:.{digits}f}"


def _short(value) -> str:
    return f"{value:.4g}" if isinstance(value, float) else str(value)


def _axis_value(axis: str, value) -> str:
    """A table cell for an axis: a case file by its name, an unset axis as '–'."""
    if value is None:
        return "–"
    if axis == "case":
        return scenes.case_name(value)
    return _short(value)


def load_text(cost: dict) -> str:
    """The machine's 1-minute load average at a run's start and end ('–' for runs recorded
    before the sweep kept it): the wall time of a run on a shared machine depends on it."""
    start, end = (cost.get("load_avg") or (None, None))
    if start is None or end is None:
        return "–"
    return f"{start:.1f}–{end:.1f}"


def _pct(value) -> str:
    return "–" if value is None else f"{100 * value:+.1f} %"


def axes_of(results: list[dict]) -> list[str]:
    """Axes whose value differs between runs (the others are listed once)."""
    keys = []
    for r in results:
        for k in r["setting"]:
            if k not in keys:
                keys.append(k)
    return [k for k in keys if len({str(r["setting"].get(k)) for r in results}) > 1]


def markdown(results: list[dict], finest_label: str | None = None, tolerance: float = 0.05) -> str:
    finest = choose_finest(results, finest_label)
    rows = sorted(with_errors(results, finest), key=lambda r: r["cost"]["cpu_s"])
    axes = axes_of(results)
    constant = {k: v for k, v in results[0]["setting"].items() if k not in axes} if results else {}
    lines = []
    if results:
        lines.append(f"Span: {results[0].get('span') or 'end time ' + str(results[0]['end_time']) + ' s'}. "
                     f"Common setting: {', '.join(f'{k} = {_short(v)}' for k, v in constant.items()) or 'none'}.")
        lines.append("")
    head = axes + ["end", "wall (s)", "load", "core-h", "CPU fluid / solid / coupler (s)", "peak RSS fluid / solid / coupler (MB)"]
    head += [title for _m, title, _s, _d in SHOWN if any(r["metrics"].get(_m) is not None for r in rows)]
    shown = [(m, t, s, d) for m, t, s, d in SHOWN if t in head]
    head += ["max error vs finest", "peak v vs reference"]
    lines.append("| " + " | ".join(head) + " |")
    lines.append("|" + "---|" * len(head))
    for r in rows:
        rss = r["cost"]["peak_rss_mb_by_program"]
        cells = [_axis_value(a, r["setting"].get(a)) for a in axes]
        kind = r["outcome"]["kind"]
        reached = r["outcome"]["reached_s"]
        cells.append(kind if kind == "completed" else f"{kind} at {_fmt(reached, 1e3, 1)} ms")
        cpu = r["cost"]["cpu_s_by_program"]
        cells += [f"{r['cost']['wall_s']:.0f}", load_text(r["cost"]), f"{r['core_hours']:.4f}",
                  " / ".join(f"{cpu.get(p, 0):.0f}" for p in ("fluid", "solid", "coupler")),
                  " / ".join(f"{rss.get(p, 0):.0f}" for p in ("fluid", "solid", "coupler"))]
        for m, _t, scale, digits in shown:
            value = r["metrics"].get(m) if usable(r) else None
            cells.append(_fmt(value, scale, digits))
        is_finest = finest is not None and r["label"] == finest["label"]
        cells.append("finest" if is_finest else _pct(r["max_error"]))
        cells.append(_pct(r.get("reference_errors", {}).get("peak_velocity")) if usable(r) else "–")
        lines.append("| " + " | ".join(cells) + " |")
    lines.append("")
    best = cheapest_within(rows, finest, tolerance)
    if finest is None:
        lines.append("No finest run completed: no errors computed.")
    elif best is None:
        lines.append(f"No cheaper run is within {100 * tolerance:g} % of the finest ({finest['label']}) on every "
                     "headline metric it has: the finest is the only setting that qualifies.")
    else:
        needed = [m for m in metrics_module.HEADLINE if finest["metrics"].get(m) is not None]
        lines.append(f"Cheapest setting within {100 * tolerance:g} % of the finest ({finest['label']}) on every "
                     f"headline metric it has ({', '.join(needed)}): **{best['label']}**, "
                     f"{best['cost']['wall_s']:.0f} s wall, {best['core_hours']:.4f} core-hours "
                     f"(finest: {finest['cost']['wall_s']:.0f} s, {finest['core_hours']:.4f} core-hours); "
                     f"it ended '{best['outcome']['kind']}', the finest '{finest['outcome']['kind']}'.")
    return "\n".join(lines) + "\n"


def chart(results: list[dict], path: Path, finest_label: str | None = None, title: str = "") -> None:
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    finest = choose_finest(results, finest_label)
    rows = [r for r in with_errors(results, finest) if r["max_error"] is not None
            and (finest is None or r["label"] != finest["label"])]
    fig, axes = plt.subplots(1, 3, figsize=(16, 4.8))
    floor = 1e-3   # errors below 0.1 % are drawn at 0.1 %
    varied = axes_of(results)
    from .stability import KIND_COLOURS
    for ax, key in ((axes[0], "wall_s"), (axes[1], "cpu_s")):
        shown_kinds = set()
        for r in rows:
            x, y = r["cost"][key], max(r["max_error"], floor)
            kind = r["outcome"]["kind"]
            ax.loglog(x, y, "o", color=KIND_COLOURS.get(kind, "black"), label=None if kind in shown_kinds else kind)
            shown_kinds.add(kind)
            ax.annotate(", ".join(_short(v) for k, v in r["setting"].items() if k in varied), (x, y), fontsize=7,
                        xytext=(3, 3), textcoords="offset points")
    markers = dict(zip(metrics_module.HEADLINE, "os^vD<>ph*"))
    plotted = set()
    for r in rows:
        for m, e in r["errors"].items():
            axes[2].loglog(r["cost"]["cpu_s"], max(abs(e), floor), markers.get(m, "x"),
                           color=f"C{list(markers).index(m)}", label=None if m in plotted else m, alpha=0.8)
            plotted.add(m)
    labels = (("wall time (s), one run at a time, shared machine", "largest headline error"),
              ("CPU time of the three programs (s)", "largest headline error"),
              ("CPU time of the three programs (s)", "each headline error"))
    for ax, (xlabel, what) in zip(axes, labels):
        ax.axhline(0.05, color="k", ls="--", lw=0.8)
        ax.set_xlabel(xlabel)
        ax.set_ylabel(f"{what} vs finest (relative)")
        ax.grid(True, which="both", alpha=0.3)
    if plotted:
        axes[2].legend(fontsize=8)
    if rows:
        axes[0].legend(fontsize=8, title="run ended", title_fontsize=8)
    fig.suptitle(title or (f"cost against error, finest = {finest['label']}" if finest else "cost against error"),
                 fontsize=9)
    fig.tight_layout()
    fig.savefig(path, dpi=120)
    plt.close(fig)
