"""Stability map: how each run of a stability sweep ended, by group, as a table and a chart.

    cd scripts && /usr/bin/python3 -m sweep stability OUTPUT [--markdown X.md] [--png X.png]
"""
from __future__ import annotations

import re
from pathlib import Path

from . import outcome, report, scenes

KIND_COLOURS = {"completed": "tab:green", "leaks": "tab:olive", "nan": "tab:red", "time-step collapse": "tab:orange",
                "solid failure": "tab:brown", "coupling divergence": "tab:purple", "energy growth": "tab:pink",
                "timeout": "tab:gray", "other": "black"}


def varied_axis(group_results: list[dict]) -> str | None:
    keys = []
    for r in group_results:
        for k in r["setting"]:
            if k not in keys:
                keys.append(k)
    varied = [k for k in keys if len({str(r["setting"].get(k)) for r in group_results}) > 1]
    return varied[0] if varied else None


def mu_of(setting: dict) -> float:
    """Explicit-coupling added-mass number mu = 2 rho_f c0 dt / (rho_s t) of a valve2d setting
    (docs/coupling-numerics.md (b); the 2 for fluid on both sides)."""
    s = {**scenes.VALVE2D_DEFAULTS, **setting}
    from valve_scene import valve2d
    window = float(s["time_step_factor"]) * valve2d.coupling_window(float(s["sound_speed"]))
    return (2 * valve2d.BLOOD_DENSITY * float(s["sound_speed"]) * window
            / (float(s["leaflet_density"]) * float(s["thickness_mm"]) * 1e-3))


def groups_of(results: list[dict], order: list | None = None) -> dict:
    """group -> its runs; the run with the base setting (the committed case) joins every group
    as its reference point."""
    groups: dict[str, list] = {}
    for r in results:
        for g in r["groups"]:
            groups.setdefault(g, []).append(r)
    shortest = min((len(r["setting"]) for r in results), default=0)
    bases = [r for r in results if len(r["setting"]) == shortest]
    if len(bases) == 1:
        base = bases[0]
        for members in groups.values():
            own = {tuple(sorted(k for k in r["setting"] if k not in base["setting"])) for r in members}
            if base not in members and len(own) == 1 and len(next(iter(own))) == 1:
                members.append(base)   # only where the group varies one axis from the base
    if order:
        rank = {g: i for i, g in enumerate(order)}
        groups = dict(sorted(groups.items(), key=lambda item: rank.get(item[0], len(rank))))
    return groups


def _value(r, axis):
    v = r["setting"].get(axis, scenes.VALVE2D_DEFAULTS.get(axis))
    try:
        return float(v)
    except (TypeError, ValueError):
        return str(v)


def _num(value, digits=3) -> str:
    return "–" if value is None else f"{value:.{digits}g}"


def markdown(results: list[dict], order: list | None = None) -> str:
    lines = []
    if results:
        lines += [f"Span: {results[0].get('span') or results[0]['end_time']}.", ""]
    lines += ["| group | setting | μ | dp / t | end | reached (ms) | stopped by | message or measure "
              "| max edge speed (m/s) | max interface force (N/m) | leaks | wall (s) | CPU (s) | load "
              "| last state written (failed runs) |",
              "|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|"]
    for group, members in groups_of(results, order).items():
        axis = varied_axis(members) or "setting"
        for r in sorted(members, key=lambda r: (str(type(_value(r, axis))), _value(r, axis))):
            s = {**scenes.VALVE2D_DEFAULTS, **r["setting"]}
            o = r["outcome"]
            shown = ", ".join(f"{k} = {v}" for k, v in r["setting"].items() if k != "material")
            # what failed (the start) and what to change (the end) both stay
            detail = outcome.shortened(re.sub(r"^(\[[^\]]*\]\s*)+", "", (o["detail"] or "")).replace("|", "/"), 440)
            reached = "–" if o["reached_s"] is None else f"{o['reached_s'] * 1e3:.1f}"
            lines.append(f"| {group} | {shown or 'default'} | {mu_of(r['setting']):.2g} | "
                         f"{float(s['spacing_mm']) / float(s['thickness_mm']):.0f} | {o['kind']} | {reached} | "
                         f"{o['detected_by'] or '(not stopped)' if o['kind'] != 'completed' else ''} | {detail} | "
                         f"{_num(r['metrics'].get('max_edge_speed'))} | {_num(r['metrics'].get('max_interface_force'))} | "
                         f"{r['metrics'].get('leaks', '–')} | "
                         f"{r['cost']['wall_s']:.0f} | {r['cost']['cpu_s']:.0f} | {report.load_text(r['cost'])} | "
                         f"{'' if o['kind'] == 'completed' else outcome.last_written_text(r['metrics'].get('last_written'))} |")
    return "\n".join(lines) + "\n"


def chart(results: list[dict], path: Path, title: str = "", order: list | None = None) -> None:
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    groups = groups_of(results, order)
    fig, axes = plt.subplots(1, len(groups), figsize=(3.0 * max(len(groups), 1), 3.6), squeeze=False)
    for ax, (group, members) in zip(axes[0], groups.items()):
        axis = varied_axis(members) or "setting"
        members = sorted(members, key=lambda r: (str(type(_value(r, axis))), _value(r, axis)))
        for i, r in enumerate(members):
            end = r["end_time"]
            reached = r["outcome"]["reached_s"] or 0.0
            kind = r["outcome"]["kind"]
            ax.bar(i, max(reached / end, 0.02), color=KIND_COLOURS.get(kind, "black"), label=kind)
            if kind != "completed":
                ax.text(i, max(reached / end, 0.02) + 0.02, kind.replace(" ", "\n"), ha="center", fontsize=6)
        ax.set_xticks(range(len(members)), [str(_value(r, axis)) for r in members], fontsize=8)
        ax.set_xlabel(axis, fontsize=8)
        ax.set_ylim(0, 1.3)
        ax.set_title(group, fontsize=9)
    axes[0][0].set_ylabel("fraction of the span reached\n(the run may still end unsound)")
    handles, labels = [], []
    for ax in axes[0]:
        for h, l in zip(*ax.get_legend_handles_labels()):
            if l not in labels:
                handles.append(h)
                labels.append(l)
    fig.legend(handles, labels, loc="lower center", ncol=len(labels), fontsize=8)
    fig.suptitle(title or "stability map: how each run ended", fontsize=9)
    fig.tight_layout(rect=(0, 0.08, 1, 1))
    fig.savefig(path, dpi=120)
    plt.close(fig)
