"""Sweeps over model settings (issue 8): cost against accuracy, and where each method fails.

    cd scripts && /usr/bin/python3 -m sweep run --preset opening-2d --output /work/runs/sweep-opening
    cd scripts && /usr/bin/python3 -m sweep report /work/runs/sweep-opening --markdown X.md --png X.png

Modules: `case_edit` (set fields of a textproto case), `scenes` (a scene and a setting -> a case
file), `runner` (one run through scripts/run_case.py with its wall time, CPU time and peak
memory per program), `metrics` (headline metrics of a run over the span it covers),
`outcome` (how a run ended, from exit code, logs and series), `report` (table, chart, the
cheapest setting within a tolerance), `presets` (the sweeps of docs/speed-accuracy.md and
docs/stability-map.md).
"""
