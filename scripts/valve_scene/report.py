"""Figures like the reference's Fig. 5 (free-edge radial position and GOA over the cycle) and
Fig. 6 (leaflet profiles in the bisection plane), and a Markdown table of the kinematic
metrics next to the reference's values.

Reference values: W. Mao, K. Li, W. Sun, Cardiovasc. Eng. Technol. 7(4), 2016 — Table 3
(RVOT, RVCT, ET; in vivo data of Leyh et al. 1999) and Section 3.2 (strain, stress).
"""
from __future__ import annotations

from pathlib import Path

import numpy as np


# Table 3 of the reference (ms); in vivo: mean and standard deviation.
REFERENCE_KINEMATICS_MS = {
    "FSI-Ogden": {"RVOT": 40, "RVCT": 35, "ET": 270},
    "FSI-MHGO": {"RVOT": 40, "RVCT": 35, "ET": 270},
    "FE-Ogden": {"RVOT": 5, "RVCT": 8, "ET": 240},
    "FE-MHGO": {"RVOT": 6, "RVCT": 9, "ET": 240},
    "in vivo": {"RVOT": "57.5 ± 11.1", "RVCT": "39.5 ± 5", "ET": "329 ± 63"},
}

# Section 3.2 of the reference: peak maximum-principal log strain and stress (MPa).
REFERENCE_PEAKS = {
    "FE-MHGO": {"strain_opening": 0.22, "strain_closed": 0.185},
    "FSI-MHGO": {"strain_opening": 0.112, "strain_closed": 0.185, "stress_closed_MPa": 1.13},
    "FSI-Ogden": {"strain_closed": 0.144, "stress_closed_MPa": 1.42},
}


def _fmt(value, scale=1.0, digits=1) -> str:
    if value is None or (isinstance(value, float) and value != value):   # None or NaN: not measured
        return "–"
    if isinstance(value, str):
        return value
    return f"{value * scale:.{digits}f}"


def kinematics_table(events_by_model: dict) -> str:
    """Markdown table: one column per measured model (ValveEvents or None), then the
    reference's columns."""
    measured = list(events_by_model)
    reference = list(REFERENCE_KINEMATICS_MS)
    header = "| metric (ms) | " + " | ".join(f"{m} (ours)" for m in measured) + " | " + \
             " | ".join(f"{r} (ref.)" for r in reference) + " |"
    rule = "|---" * (1 + len(measured) + len(reference)) + "|"
    rows = [header, rule]
    for metric, attribute in (("RVOT", "rvot"), ("RVCT", "rvct"), ("ET", "et")):
        ours = [_fmt(getattr(events_by_model[m], attribute) if events_by_model[m] else None, 1e3)
                for m in measured]
        theirs = [str(REFERENCE_KINEMATICS_MS[r][metric]) for r in reference]
        rows.append(f"| {metric} | " + " | ".join(ours) + " | " + " | ".join(theirs) + " |")
    return "\n".join(rows) + "\n"


def plot_kinematics(series_by_model: dict, path: Path, t_max: float = 0.4) -> None:
    """Like the reference's Fig. 5: (a) mean free-edge radial position, (b) GOA, over
    0..t_max. series_by_model[name] = dict(time_s, free_edge_radial_position_m, goa_m2)."""
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    fig, (a, b) = plt.subplots(1, 2, figsize=(11, 4))
    for name, s in series_by_model.items():
        t = np.asarray(s["time_s"])
        keep = t <= t_max
        a.plot(t[keep] * 1e3, np.asarray(s["free_edge_radial_position_m"])[keep] * 1e3, label=name)
        b.plot(t[keep] * 1e3, np.asarray(s["goa_m2"])[keep] * 1e4, label=name)
    a.set_xlabel("time (ms)")
    a.set_ylabel("free-edge midpoint radial position (mm)")
    a.set_title("(a) leaflet free edge, mean of the leaflets")
    b.set_xlabel("time (ms)")
    b.set_ylabel("geometric orifice area (cm²)")
    b.set_title("(b) GOA, top-view projection")
    for ax in (a, b):
        ax.grid(alpha=0.3)
        ax.legend(fontsize=8)
    fig.tight_layout()
    fig.savefig(path, dpi=120)
    plt.close(fig)


def plot_profiles(profiles: dict, path: Path, closing_from_s: float, title: str = "") -> None:
    """Like the reference's Fig. 6: profiles[time_s] = [(radial, z)] polylines; red before
    `closing_from_s` (opening), blue from it on (closing)."""
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    fig, ax = plt.subplots(figsize=(5, 5))
    for t, line in sorted(profiles.items()):
        line = np.asarray(line)
        if len(line) == 0:
            continue
        color = "tab:red" if t < closing_from_s else "tab:blue"
        ax.plot(line[:, 0] * 1e3, line[:, 1] * 1e3, color=color, lw=1)
        ax.annotate(f"{t * 1e3:.0f}", (line[-1, 0] * 1e3, line[-1, 1] * 1e3), fontsize=6, color=color)
    ax.set_xlabel("radial coordinate in the bisection plane (mm)")
    ax.set_ylabel("z (mm)")
    ax.set_aspect("equal")
    ax.grid(alpha=0.3)
    ax.set_title(title or "leaflet profiles (red opening, blue closing; labels in ms)")
    fig.tight_layout()
    fig.savefig(path, dpi=120)
    plt.close(fig)


def write_markdown_report(path: Path, title: str, events_by_model: dict, figures: list[str],
                          notes: str = "") -> None:
    """A report page: the kinematics table against the reference, the figures, notes."""
    lines = [f"# {title}", "", "## Kinematics (reference Table 3)", "", kinematics_table(events_by_model)]
    lines += ["Definitions: docs/valve-scene.md (\"Analysis\"): 10 %–90 % levels of the free-edge "
              "radial excursion.", ""]
    for figure in figures:
        lines += [f"![{Path(figure).stem}]({figure})", ""]
    if notes:
        lines += ["## Notes", "", notes, ""]
    Path(path).write_text("\n".join(lines))
