"""``lumpbeam diagnose BAG``: the model-discrepancy workflow of doc/interfaces.md."""

from __future__ import annotations

import argparse
import sys
import time
from pathlib import Path

from lumpbeam_ros.apps.cli.output import write_json
from lumpbeam_ros.base.errors import LumpbeamError
from lumpbeam_ros.core.diagnose.live import named_effects
from lumpbeam_ros.core.diagnose.measurement import read_record
from lumpbeam_ros.core.diagnose.workflow import Diagnosis, diagnose
from lumpbeam_ros.core.model.parameters import load_beam_config, write_beam_config


def _summary(d: Diagnosis, seconds: float) -> str:
    lines = [
        f'missing effect: {verdict_text(d)}',
        f'  missing effects: {" + ".join(e.name for e in d.missing_effects) or "-"} '
        f'(confidence {d.confidence:.3g})',
        f'  {d.decision.reason}',
        f'  noise: z {d.noise_z_m * 1e6:.1f} um, pitch {d.noise_pitch_rad * 1e6:.1f} urad',
    ]
    gaps = (
        ('configured', d.gap_configured),
        ('gap before', d.gap_before),
        ('gap after ', d.gap_after),
    )
    for label, gap in gaps:
        lines.append(
            f'  {label}: rms {gap.rms_m * 1e6:9.1f} um  max {gap.max_m * 1e6:9.1f} um  '
            f'frequency {gap.frequency_error:+.2e}  damping {gap.damping_error:+.2e}'
        )
    lines.append(f'  {"candidate":<18} {"BIC":>14} {"held-out chi2/n":>16}  parameter')
    for s in [d.nominal, *d.candidates]:
        effect = {k: v for k, v in s.parameters.items() if k not in _REFIT}
        shown = ', '.join(f'{k} = {v:.4g}' for k, v in effect.items()) or '-'
        flag = '' if s.physical else '  (unphysical)'
        lines.append(f'  {s.name:<18} {s.bic:>14.1f} {s.holdout_chi2:>16.3f}  {shown}{flag}')
    lines.append(f'  {d.simulations} simulations in {seconds:.1f} s')
    return '\n'.join(lines)


_REFIT = ('k_total_nm_per_rad', 'beta_identified')


def verdict_text(d: Diagnosis) -> str:
    """The verdict: each named effect beside its own parameters (``'none'``, ``'unexplained'``)."""
    named = named_effects(d)
    if not named:
        return d.missing_effect
    return ' + '.join(
        name + ''.join(f' ({k} = {v:.4g})' for k, v in parameters.items())
        for name, parameters in named
    )


def run(args: argparse.Namespace) -> int:
    """Diagnoses the bag, prints the verdict and writes the requested outputs."""
    beam, drop = load_beam_config(args.config)
    if not Path(args.bag).is_dir():
        raise LumpbeamError(f'{args.bag}: no such bag folder')
    record = read_record(args.bag)
    for note in record.notes:
        print(f'lumpbeam diagnose: warning: {args.bag}: {note}', file=sys.stderr)
    start = time.perf_counter()
    result = diagnose(record, beam)
    print(_summary(result, time.perf_counter() - start))
    if args.json:
        write_json(args.json, result.as_dict())
    if args.plots:
        from lumpbeam_ros.apps.plots.diagnosis import plot_diagnosis  # matplotlib only when asked

        for path in plot_diagnosis(result, args.plots):
            print(f'  wrote {path}')
    if args.report:
        from lumpbeam_ros.apps.report.diagnosis import write_diagnosis_report

        print(f'  wrote {write_diagnosis_report(result, args.bag, args.report)}')
    if args.write_model:
        header = (
            f'Written by lumpbeam diagnose from {args.bag}: missing effect '
            f'{" + ".join(e.name for e in result.missing_effects) or result.missing_effect}.'
            f'\n{result.decision.reason}\n'
            'k_total_nm_per_rad and beta_identified are refit on the record with the effects.'
        )
        try:
            write_beam_config(args.write_model, result.augmented_beam, drop, header)
        except OSError as exc:
            raise LumpbeamError(
                f'cannot write the model to {args.write_model}: {exc.strerror or exc}'
            ) from None
        print(f'  wrote {args.write_model}')
    return 0
