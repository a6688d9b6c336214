"""Left-ventricular and aortic pressure at 75 bpm (0.8 s), t = 0 at the start of ejection.

Construction (documented in docs/valve-scene.md):
  1. A piecewise-linear trace through textbook Wiggers-diagram values (aortic 80/120 mmHg,
     LV end-diastolic pressure ~12 mmHg, incisura, diastolic LV ~2 mmHg), with two analytic
     pieces sampled every 5 ms: LV isovolumic relaxation as the mono-exponential decay of
     Weiss et al. (1976), tau = 30 ms, and the aortic diastolic run-off as a Windkessel
     exponential decay.
  2. Each trace convolved with a Gaussian of width SMOOTHING_SIGMA_S, in closed form over
     the periodically unrolled trace. The result is infinitely smooth, periodic (also at the
     cycle joint), stays within the bounds of the knots (no overshoot), and -- the
     convolution being linear -- the transvalvular difference is the same smoothing applied
     to the knot differences.
The timings are set so that the difference dp = p_LV - p_Ao crosses zero at ~0.235 s (the
reference's FE-only valve is closed at 240 ms), reaches ~-97 mmHg in early diastole (the
reference's 5.4 N = Pmax*A on the size-23 annulus) and ~-70 mmHg at end diastole.
"""
from __future__ import annotations

import argparse
import math
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from . import MMHG_TO_PA

PERIOD_S = 0.8                 # 75 beats per minute
SMOOTHING_SIGMA_S = 0.003      # Gaussian width: rounds the valve-event kinks over a few ms
SAMPLE_INTERVAL_S = 0.001      # table spacing written to the case files
# The smoothing moves the upward zero crossing of dp from the 0 s knot to 1.88 ms; the traces
# are evaluated that much later so that dp crosses zero upward at t = 0 exactly.
OPENING_SHIFT_S = 0.00188

VALVE_CLOSURE_S = 0.245        # knot time of aortic-valve closure (LV = Ao); smoothing moves the crossing ~5 ms earlier
LV_RELAXATION_TAU_S = 0.030    # isovolumic relaxation time constant (Weiss et al. 1976; normal 30-40 ms)
AORTIC_RUNOFF_START_S = 0.270  # dicrotic wave crest, start of the diastolic run-off
AORTIC_RUNOFF_START_MMHG = 106.0
AORTIC_DIASTOLIC_MMHG = 80.0   # at the end of diastole = at aortic-valve opening (t = 0)

# Aortic pressure during ejection and the incisura (time s, mmHg).
_AORTIC_EJECTION_KNOTS = [
    (0.000, 80.0), (0.020, 86.0), (0.040, 94.0), (0.060, 101.0), (0.080, 107.0),
    (0.100, 112.0), (0.120, 116.0), (0.140, 118.5), (0.160, 119.5), (0.180, 118.5),
    (0.200, 116.0), (0.220, 110.5), (VALVE_CLOSURE_S, 107.0),
    (0.255, 103.5),                                   # incisura
    (AORTIC_RUNOFF_START_S, AORTIC_RUNOFF_START_MMHG),  # dicrotic wave
]

# LV pressure above aortic pressure during ejection (time s, mmHg): the forward driving
# difference, steepest early (acceleration of the stroke volume) and decaying to zero at
# closure.
_EJECTION_EXCESS_KNOTS = [
    (0.000, 0.0), (0.010, 5.0), (0.020, 9.0), (0.025, 10.0), (0.035, 9.6), (0.050, 8.2),
    (0.070, 6.6), (0.090, 5.4), (0.110, 4.4), (0.130, 3.6), (0.150, 2.9), (0.170, 2.2),
    (0.190, 1.5), (0.210, 0.8), (0.225, 0.35), (VALVE_CLOSURE_S, 0.0),
]

# Diastolic filling pressure added to the relaxation exponential (time s, mmHg): slow
# filling, atrial contraction (peak ~0.73 s), end-diastolic pressure at mitral closure.
_LV_FILLING_KNOTS = [
    (VALVE_CLOSURE_S, 0.0), (0.360, 1.5), (0.450, 3.0), (0.600, 4.5), (0.680, 6.0),
    (0.700, 7.5), (0.730, 12.0), (0.750, 11.5),
]

# Isovolumic contraction, mitral closure to aortic opening (time s, mmHg).
_LV_CONTRACTION_KNOTS = [
    (0.760, 15.0), (0.770, 23.0), (0.780, 36.0), (0.790, 56.0), (PERIOD_S, 80.0),
]


def _interp_knots(knots, t):
    times, values = zip(*knots)
    return np.interp(t, times, values)


def aortic_knots() -> tuple[np.ndarray, np.ndarray]:
    """Piecewise-linear aortic trace over [0, PERIOD_S] (s, mmHg), before smoothing."""
    t_runoff = np.arange(AORTIC_RUNOFF_START_S + 0.025, PERIOD_S + 1e-12, 0.025)
    # Windkessel run-off: exponential decay with the time constant that lands on the
    # diastolic pressure at the next opening.
    tau = (PERIOD_S - AORTIC_RUNOFF_START_S) / math.log(AORTIC_RUNOFF_START_MMHG / AORTIC_DIASTOLIC_MMHG)
    p_runoff = AORTIC_RUNOFF_START_MMHG * np.exp(-(t_runoff - AORTIC_RUNOFF_START_S) / tau)
    t = np.concatenate([[k[0] for k in _AORTIC_EJECTION_KNOTS], t_runoff])
    p = np.concatenate([[k[1] for k in _AORTIC_EJECTION_KNOTS], p_runoff])
    p[-1] = AORTIC_DIASTOLIC_MMHG
    t[-1] = PERIOD_S
    return t, p


def ventricular_knots() -> tuple[np.ndarray, np.ndarray]:
    """Piecewise-linear LV trace over [0, PERIOD_S] (s, mmHg), before smoothing."""
    t_ao, p_ao = aortic_knots()
    # Knots at every aortic and excess knot of ejection, so that LV - Ao between knots is
    # exactly the interpolated excess.
    t_ej = np.union1d([k[0] for k in _EJECTION_EXCESS_KNOTS], t_ao[t_ao <= VALVE_CLOSURE_S])
    p_ej = np.interp(t_ej, t_ao, p_ao) + _interp_knots(_EJECTION_EXCESS_KNOTS, t_ej)
    p_closure = p_ej[-1]
    t_dia = np.arange(VALVE_CLOSURE_S + 0.005, 0.750 + 1e-12, 0.005)
    p_dia = (p_closure * np.exp(-(t_dia - VALVE_CLOSURE_S) / LV_RELAXATION_TAU_S)
             + _interp_knots(_LV_FILLING_KNOTS, t_dia))
    t_ivc = np.array([k[0] for k in _LV_CONTRACTION_KNOTS])
    p_ivc = np.array([k[1] for k in _LV_CONTRACTION_KNOTS])
    return np.concatenate([t_ej, t_dia, t_ivc]), np.concatenate([p_ej, p_dia, p_ivc])


def _normal_cdf(x: np.ndarray) -> np.ndarray:
    # beyond 9 standard deviations the CDF is 0 or 1 to double precision: skip erf there
    result = (x > 0).astype(float)
    near = np.abs(x) < 9.0
    result[near] = 0.5 * (1.0 + np.vectorize(math.erf)(x[near] / math.sqrt(2.0)))
    return result


def _normal_pdf(x: np.ndarray) -> np.ndarray:
    return np.exp(-0.5 * x * x) / math.sqrt(2.0 * math.pi)


@dataclass(frozen=True)
class SmoothPeriodicTrace:
    """A periodic piecewise-linear trace convolved with a Gaussian, evaluated in closed form."""
    knot_times: np.ndarray   # over [0, period], first and last value equal
    knot_values: np.ndarray
    period: float
    sigma: float
    shift: float = 0.0       # the trace is evaluated at t + shift

    def __call__(self, t) -> np.ndarray:
        t = np.mod(np.atleast_1d(np.asarray(t, dtype=float)) + self.shift, self.period)
        # Unroll one period either side: the Gaussian tail beyond that is < 1e-100.
        times = np.concatenate([self.knot_times[:-1] - self.period, self.knot_times[:-1],
                                self.knot_times + self.period])
        values = np.concatenate([self.knot_values[:-1], self.knot_values[:-1], self.knot_values])
        a, b = times[:-1], times[1:]
        fa = values[:-1]
        slope = (values[1:] - fa) / (b - a)
        ua = (a[None, :] - t[:, None]) / self.sigma
        ub = (b[None, :] - t[:, None]) / self.sigma
        # Integral of (fa + slope (s - a)) * gaussian(t - s) over each segment [a, b].
        level = fa[None, :] + slope[None, :] * (t[:, None] - a[None, :])
        result = (level * (_normal_cdf(ub) - _normal_cdf(ua))
                  + slope[None, :] * self.sigma * (_normal_pdf(ua) - _normal_pdf(ub)))
        return result.sum(axis=1)


def aortic_pressure_mmHg() -> SmoothPeriodicTrace:
    t, p = aortic_knots()
    return SmoothPeriodicTrace(t, p, PERIOD_S, SMOOTHING_SIGMA_S, OPENING_SHIFT_S)


def ventricular_pressure_mmHg() -> SmoothPeriodicTrace:
    t, p = ventricular_knots()
    return SmoothPeriodicTrace(t, p, PERIOD_S, SMOOTHING_SIGMA_S, OPENING_SHIFT_S)


def transvalvular_pressure_mmHg(t) -> np.ndarray:
    """dp = p_LV - p_Ao (mmHg); > 0 opens the valve."""
    return ventricular_pressure_mmHg()(t) - aortic_pressure_mmHg()(t)


def sampled_table(interval_s: float = SAMPLE_INTERVAL_S):
    """(time_s, p_lv_mmHg, p_ao_mmHg) sampled over [0, PERIOD_S)."""
    count = int(round(PERIOD_S / interval_s))
    t = np.arange(count) * interval_s
    return t, ventricular_pressure_mmHg()(t), aortic_pressure_mmHg()(t)


def _format_list(values, fmt: str, per_line: int = 10, indent: str = "    ") -> str:
    items = [fmt.format(v) for v in values]
    lines = [", ".join(items[i:i + per_line]) for i in range(0, len(items), per_line)]
    return "[\n" + indent + (",\n" + indent).join(lines) + "\n  ]"


def waveform_textproto(interval_s: float = SAMPLE_INTERVAL_S) -> str:
    """The `waveform { ... }` block of a case file (message valvefsi.cases.PressureWaveform)."""
    t, p_lv, p_ao = sampled_table(interval_s)
    return (
        "waveform {\n"
        f"  period_s: {PERIOD_S:g}\n"
        f"  time_s: {_format_list(t, '{:.3f}')}\n"
        f"  ventricular_pressure_mmHg: {_format_list(p_lv, '{:.3f}')}\n"
        f"  aortic_pressure_mmHg: {_format_list(p_ao, '{:.3f}')}\n"
        "}\n"
    )


FRAGMENT_HEADER = """\
# Left-ventricular and aortic pressure at 75 bpm (0.8 s), t = 0 at the start of ejection,
# sampled every 1 ms (valvefsi.cases.PressureWaveform). Generated, do not edit:
#   cd scripts && /usr/bin/python3 -m valve_scene.waveform --textproto ../cases/waveforms/wiggers-75bpm.textproto
# Construction and sources: docs/valve-scene.md ("Pressure waveform").
"""


def plot(path: Path) -> None:
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    t = np.linspace(0.0, PERIOD_S, 1601)
    p_lv, p_ao = ventricular_pressure_mmHg()(t), aortic_pressure_mmHg()(t)
    fig, (top, bottom) = plt.subplots(2, 1, figsize=(7, 6.5), sharex=True)
    top.plot(t * 1e3, p_ao, label="aortic")
    top.plot(t * 1e3, p_lv, label="left ventricle")
    top.set_ylabel("pressure (mmHg)")
    top.set_title("Wiggers pressures at 75 bpm, t = 0 at aortic-valve opening")
    top.legend()
    top.grid(alpha=0.3)
    bottom.plot(t * 1e3, p_lv - p_ao, color="k")
    bottom.axhline(0.0, color="0.6", lw=0.8)
    bottom.set_xlabel("time (ms)")
    bottom.set_ylabel("dp = p_LV - p_Ao (mmHg)")
    bottom.grid(alpha=0.3)
    inset = bottom.inset_axes([0.42, 0.42, 0.55, 0.5])
    early = t <= 0.26
    inset.plot(t[early] * 1e3, (p_lv - p_ao)[early], color="k")
    inset.axhline(0.0, color="0.6", lw=0.8)
    inset.set_ylim(-5, 12)
    inset.set_title("ejection", fontsize=8)
    inset.tick_params(labelsize=7)
    fig.tight_layout()
    fig.savefig(path, dpi=120)
    plt.close(fig)


def summary() -> dict:
    """The waveform's characteristic numbers (also what the tests check)."""
    t = np.arange(0.0, PERIOD_S, 1e-4)
    dp = transvalvular_pressure_mmHg(t)
    forward = dp > 0
    ejection_end = t[np.argmax((~forward) & (t > 0.1))]
    ejection = (t > 0.0) & (t < ejection_end)
    i_min = int(np.argmin(dp))
    return {
        "peak_forward_dp_mmHg": float(dp[ejection].max()),
        "time_of_peak_forward_dp_s": float(t[ejection][np.argmax(dp[ejection])]),
        "mean_forward_dp_mmHg": float(dp[ejection].mean()),
        "dp_zero_crossing_s": float(ejection_end),
        "diastolic_min_dp_mmHg": float(dp[i_min]),
        "time_of_diastolic_min_s": float(t[i_min]),
        "end_diastolic_dp_mmHg": float(transvalvular_pressure_mmHg(0.75)[0]),
        "hydrostatic_force_on_size23_annulus_N": float(-dp[i_min] * MMHG_TO_PA * math.pi * 0.0115 ** 2),
    }


def main(argv=None) -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--textproto", type=Path, help="write the waveform block (textproto fragment) here")
    parser.add_argument("--png", type=Path, help="write the plot here")
    args = parser.parse_args(argv)
    if args.textproto:
        args.textproto.parent.mkdir(parents=True, exist_ok=True)
        args.textproto.write_text(FRAGMENT_HEADER + waveform_textproto())
    if args.png:
        args.png.parent.mkdir(parents=True, exist_ok=True)
        plot(args.png)
    for key, value in summary().items():
        print(f"{key}: {value:.4g}")


if __name__ == "__main__":
    main()
