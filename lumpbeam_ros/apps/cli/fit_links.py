"""``lumpbeam analyze BAG... --arm FILE --fit-links|--fit-payload [--write-arm OUT]``.

Each link's k_tE and damping, or the payload, from the modes measured after each bag's last
move; with ``--write-arm``, the arm file with the fitted values.
"""

from __future__ import annotations

import argparse
import sys

from lumpbeam_ros.apps.cli.output import write_json
from lumpbeam_ros.base.errors import LumpbeamError
from lumpbeam_ros.core.ident.arm.bag_modes import bag_observations
from lumpbeam_ros.core.ident.arm.link_fit import (
    LinkFit,
    LinkParameterFit,
    ModeObservation,
    link_stiffness_total,
)
from lumpbeam_ros.core.ident.arm.payload_fit import PayloadEstimate, PayloadFit
from lumpbeam_ros.core.ident.settings import load_identifier_config, with_max_modes
from lumpbeam_ros.core.model.arm.config import ArmConfig, load_arm_config, write_arm_config


def _observations(
    args: argparse.Namespace, option: str
) -> tuple[ArmConfig, list[ModeObservation]]:
    """The arm file and each bag's final joints and ring-down modes, printed."""
    if not args.arm:
        raise LumpbeamError(f'{option} needs --arm FILE (the arm the bags were recorded on)')
    arm = load_arm_config(args.arm)
    config = load_identifier_config(args.identifier_config)
    if args.max_modes is not None:
        config = with_max_modes(config, args.max_modes)
    observations = bag_observations(args.bag, arm, config)
    for obs in observations:
        angles = ', '.join(f'{v:.4g}' for v in obs.joint_angles_rad)
        modes = ', '.join(
            f'{m.natural_frequency_hz:.4f} Hz (zeta {m.damping_ratio:.3g})' for m in obs.modes
        )
        print(f'{obs.label}: q = {angles} rad: {len(obs.modes)} mode(s): {modes}')
    return arm, observations


def _bags_json(observations: list[ModeObservation]) -> list[dict[str, object]]:
    return [
        {
            'bag': obs.label,
            'joint_angles_rad': obs.joint_angles_rad.tolist(),
            'modes': [vars(m) for m in obs.sorted_modes()],
        }
        for obs in observations
    ]


def _reduced(fit: LinkFit | PayloadEstimate) -> str:
    return f', reduced chi^2 {fit.chi2 / fit.dof:.3g}' if fit.dof > 0 else ''


def _finish(
    args: argparse.Namespace,
    fit: LinkFit | PayloadEstimate,
    observations: list[ModeObservation],
    what: str,
) -> None:
    """The fit's warnings on stderr, then the arm file (``--write-arm``) and the JSON."""
    for line in fit.warnings():
        print(f'lumpbeam analyze: warning: {line}', file=sys.stderr)
    if args.write_arm:
        header = (
            f'lumpbeam analyze: {what} fitted to the bags {", ".join(args.bag)} from {args.arm}'
        )
        write_arm_config(args.write_arm, fit.arm, header=header)
        print(f'wrote {args.write_arm}')
    if args.json:
        write_json(args.json, {**fit.as_json(), 'bags': _bags_json(observations)})


def run_fit_links(args: argparse.Namespace) -> int:
    """Reads each bag's final joints and ring-down modes, fits the links, prints and writes them.

    Raises:
        LumpbeamError: ``--fit-links`` without ``--arm``, and everything
            :func:`~lumpbeam_ros.core.ident.arm.bag_modes.bag_observations` and
            :meth:`~lumpbeam_ros.core.ident.arm.link_fit.LinkParameterFit.fit` refuse.
    """
    arm, observations = _observations(args, '--fit-links')
    fit = LinkParameterFit(arm).fit(observations)
    print(
        f'{args.arm}: {arm.n_joints} link(s) fitted to '
        f'{sum(len(o.modes) for o in observations)} mode(s) of {len(observations)} bag(s)'
        f'{_reduced(fit)}'
    )
    for i, (link, nominal) in enumerate(zip(fit.links, arm.links, strict=True), start=1):
        print(
            f'  link {i}: k_total {link.k_total_nm_per_rad:.6g} +- '
            f'{link.k_total_nm_per_rad_std:.3g} N m/rad (nominal '
            f'{link_stiffness_total(nominal):.6g}), damping_beta {link.damping_beta:.4g} +- '
            f'{link.damping_beta_std:.2g} s (nominal {nominal.damping_beta:.4g})'
        )
    _finish(args, fit, observations, 'links')
    return 0


def run_fit_payload(args: argparse.Namespace) -> int:
    """Reads each bag's final joints and ring-down modes, fits the payload, prints, writes it.

    Raises:
        LumpbeamError: ``--fit-payload`` without ``--arm``, and everything
            :func:`~lumpbeam_ros.core.ident.arm.bag_modes.bag_observations` and
            :meth:`~lumpbeam_ros.core.ident.arm.payload_fit.PayloadFit.fit` refuse.
    """
    arm, observations = _observations(args, '--fit-payload')
    fit = PayloadFit(arm).fit(observations)
    print(
        f'{args.arm}: payload {fit.payload_kg:.5g} +- {fit.payload_kg_std:.2g} kg (file: '
        f'{arm.payload_kg:.5g} kg) from {sum(len(o.modes) for o in observations)} mode(s) of '
        f'{len(observations)} bag(s){_reduced(fit)}'
    )
    _finish(args, fit, observations, 'payload')
    return 0
