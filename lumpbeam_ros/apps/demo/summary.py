"""The demo's results: its figures, its summary table and ``summary.json``.

Measured against predicted (Figs. B.8-B.10); identified, live, truth and the paper's figures.
"""

from __future__ import annotations

import math
from pathlib import Path
from typing import Any

from lumpbeam_ros.apps.demo.live_diagnosis import (
    live_diagnosis,
    live_diagnosis_lines,
)
from lumpbeam_ros.apps.demo.recording import (
    live_value,
    prediction_lag,
)
from lumpbeam_ros.apps.demo.run import (
    PAPER,
    DemoRun,
    analysis_of,
)
from lumpbeam_ros.apps.json_output import write_json
from lumpbeam_ros.core.bagio import BagReader
from lumpbeam_ros.core.model.adopt import first_mode
from lumpbeam_ros.core.viz.markers import MARKERS_TOPIC


def figures(run: DemoRun) -> None:
    """Draws measured against predicted (whole record, and the release) with the residual."""
    from lumpbeam_ros.apps.plots.demo import plot_measured_vs_predicted

    analysis = analysis_of(run)
    release = run.drop.release_time_s
    folder = run.out / 'figures'
    run.figures = [
        plot_measured_vs_predicted(
            analysis.residual,
            folder / 'tip_measured_vs_predicted.png',
            release_time_s=release,
        ),
        plot_measured_vs_predicted(
            analysis.residual,
            folder / 'tip_release_zoom.png',
            span=(release - 0.5, release + 3.0),
            release_time_s=release,
            title='Tip after the release: measured and predicted',
        ),
    ]
    if run.with_camera:
        run.figures.append(_camera_figure(run, folder / 'tip_tracked_vs_truth.png'))
    if MARKERS_TOPIC in BagReader(run.normalized_bag).topics:
        run.figures.append(_beam_figure(run, folder / 'beam_markers.png'))


def _beam_figure(run: DemoRun, path: Path) -> Path:
    """Draws the recorded ``/beam_markers`` around the release (what a viewer shows)."""
    from lumpbeam_ros.apps.plots.beam import drop_snapshot_times, plot_beam_snapshots

    f_n, _, _ = first_mode(run.beam, 0.0)
    release = run.drop.release_time_s
    return plot_beam_snapshots(
        run.normalized_bag,
        path,
        times=drop_snapshot_times(release, 1.0 / f_n),
        release_time_s=release,
        title="The beam in the demo's recording, as /beam_markers draw it",
    )


def _camera_figure(run: DemoRun, path: Path) -> Path:
    """Draws the camera node's poses against the motion its frames showed (noise-free)."""
    from lumpbeam_ros.apps.plots.demo import plot_measured_vs_predicted, prediction_residual
    from lumpbeam_ros.core.synthetic.drop_test import SynthOptions, simulate_experiment

    options = SynthOptions(duration_s=run.options.duration_s, effects=run.options.effects)
    seen, _ = simulate_experiment(run.beam, run.drop, options)
    tracked = analysis_of(run).measured
    residual = prediction_residual(tracked.t, tracked.z, seen.t, seen.z)
    run.camera_rms_m = residual.rms()
    return plot_measured_vs_predicted(
        residual,
        path,
        release_time_s=run.drop.release_time_s,
        title='Tip: tracked by the camera node and as the camera saw it',
        labels=('camera node /tip_pose', 'synthetic truth (what the frames show)'),
    )


def summarize(run: DemoRun) -> None:
    """Builds the summary (identified, live, truth, paper), prints it, writes summary.json."""
    analysis = analysis_of(run)
    ident = analysis.identification
    f_n, _, zeta = first_mode(run.beam, 0.0)
    truth = {
        'natural_frequency_hz': f_n,
        'damping_ratio': zeta,
        'stiffness_total_nm_per_rad': run.beam.k_total_nm_per_rad,
    }
    rows = {}
    for key in truth:
        rows[key] = {
            'identified': ident.figure(key).value,
            'identified_std': ident.figure(key).std,
            'live': live_value(analysis, key),
            'truth': truth[key],
            'paper': PAPER[key],
        }
    residual = analysis.residual
    after = run.drop.release_time_s
    lag, aligned_rms = prediction_lag(analysis.measured, analysis.predicted, after)
    run.summary = {
        'status': ident.status.name,
        'release_time_s': ident.release.time_s.value,
        'quantities': rows,
        'prediction_rms_m': residual.rms(),
        'prediction_rms_after_release_m': residual.rms(start=after),
        'prediction_max_m': float(abs(residual.residual).max()),
        'prediction_lag_s': lag,
        'prediction_rms_aligned_m': aligned_rms,
        'measured_samples': int(analysis.measured.t.size),
        'predicted_samples': int(analysis.predicted.t.size),
        'nodes': list(run.nodes),
        'topic_counts': run.topic_counts,
        'image_counts': run.image_counts,
        'with_camera': run.with_camera,
        'camera_rms_m': run.camera_rms_m,
        'figures': [str(p) for p in run.figures],
        'step_seconds': dict(run.step_seconds),
    }
    if run.diagnosis is not None:
        run.summary['diagnosis'] = run.diagnosis
    live = live_diagnosis(run.recorded_bag, analysis, run.drop.release_time_s)
    if live is not None:
        run.summary['live_diagnosis'] = live
    for line in summary_lines(run.summary):
        run.echo(line)
    write_json(run.out / 'summary.json', run.summary)


def summary_lines(summary: dict[str, Any]) -> list[str]:
    """The human summary table of :func:`summarize` (also of its JSON read back)."""
    labels = {
        'natural_frequency_hz': ('natural frequency', 'Hz', '{:.4f}'),
        'damping_ratio': ('damping ratio', '', '{:.5f}'),
        'stiffness_total_nm_per_rad': ('k_tE (B.12)', 'N m/rad', '{:.1f}'),
    }
    lines = [
        f'{"quantity":<24}{"identified (offline)":>26}{"live node":>12}{"truth":>12}{"paper":>10}',
    ]
    for key, (label, unit, fmt) in labels.items():
        row = summary['quantities'][key]
        ident = f'{fmt.format(row["identified"])} +- {row["identified_std"]:.2g}'
        live = row['live']  # NaN in a run, None when read back from summary.json
        live = fmt.format(live) if live is not None and math.isfinite(live) else '-'
        name = f'{label} ({unit})' if unit else label
        lines.append(
            f'{name:<24}{ident:>26}{live:>12}{fmt.format(row["truth"]):>12}'
            f'{fmt.format(row["paper"]):>10}'
        )
    lines.append(
        f'prediction vs measurement: RMS {summary["prediction_rms_m"] * 1e3:.3f} mm '
        f'({summary["prediction_rms_after_release_m"] * 1e3:.3f} mm after the release), '
        f'max {summary["prediction_max_m"] * 1e3:.3f} mm over {summary["measured_samples"]} '
        f'samples'
    )
    if summary.get('prediction_lag_s') is not None and math.isfinite(summary['prediction_lag_s']):
        lines.append(
            f'  of which timing: the prediction runs {summary["prediction_lag_s"] * 1e3:.1f} ms '
            f'late (the latency the camera hides, until the simulator adopts it); '
            f'shifted by it, RMS '
            f'{summary["prediction_rms_aligned_m"] * 1e3:.3f} mm after the release'
        )
    if summary.get('camera_rms_m') is not None:
        lines.append(
            f'camera node vs the synthetic truth: RMS {summary["camera_rms_m"] * 1e6:.1f} um '
            f'in tip z'
        )
    if 'diagnosis' in summary:
        lines += diagnosis_lines(summary['diagnosis'])
    if 'live_diagnosis' in summary:
        lines += live_diagnosis_lines(summary['live_diagnosis'])
    return lines


def diagnosis_lines(diagnosis: dict[str, Any]) -> list[str]:
    """The diagnosis in two lines: the effect found and the gap before and after adding it."""
    found = diagnosis.get('missing_effect')
    parameters = ', '.join(
        f'{k} = {v:.4g}' for k, v in (diagnosis.get('effect_parameters') or {}).items()
    )
    lines = [f'diagnosis: missing effect {found}' + (f' ({parameters})' if parameters else '')]
    before, after = diagnosis.get('gap_before'), diagnosis.get('gap_after')
    if before and after:
        lines.append(
            f'  gap to the measurement: RMS {before["rms_m"] * 1e3:.3f} mm with the nominal '
            f'model, {after["rms_m"] * 1e3:.3f} mm with the effect added'
        )
    return lines
