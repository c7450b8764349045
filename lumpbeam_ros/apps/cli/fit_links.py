"""``lumpbeam analyze BAG... --arm FILE --fit-links``: each link's k_tE and damping from data."""

from __future__ import annotations

import argparse
import sys

from lumpbeam_ros.apps.cli.output import write_json
from lumpbeam_ros.base.errors import LumpbeamError
from lumpbeam_ros.core.ident.arm.bag_modes import bag_observations
from lumpbeam_ros.core.ident.arm.link_fit import LinkParameterFit, link_stiffness_total
from lumpbeam_ros.core.ident.settings import load_identifier_config, with_max_modes
from lumpbeam_ros.core.model.arm.config import load_arm_config


def run_fit_links(args: argparse.Namespace) -> int:
    """Reads each bag's final joints and ring-down modes, fits the links, prints and writes them.

    Raises:
        LumpbeamError: ``--fit-links`` without ``--arm``, and everything
            :func:`~lumpbeam_ros.core.ident.arm.bag_modes.bag_observations` and
            :meth:`~lumpbeam_ros.core.ident.arm.link_fit.LinkParameterFit.fit` refuse.
    """
    if not args.arm:
        raise LumpbeamError('--fit-links needs --arm FILE (the arm the bags were recorded on)')
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
    fit = LinkParameterFit(arm).fit(observations)
    reduced = f', reduced chi^2 {fit.chi2 / fit.dof:.3g}' if fit.dof > 0 else ''
    print(
        f'{args.arm}: {arm.n_joints} link(s) fitted to '
        f'{sum(len(o.modes) for o in observations)} mode(s) of {len(observations)} bag(s)'
        f'{reduced}'
    )
    for i, (link, nominal) in enumerate(zip(fit.links, arm.links, strict=True), start=1):
        print(
            f'  link {i}: k_total {link.k_total_nm_per_rad:.6g} +- '
            f'{link.k_total_nm_per_rad_std:.3g} N m/rad (nominal '
            f'{link_stiffness_total(nominal):.6g}), damping_beta {link.damping_beta:.4g} +- '
            f'{link.damping_beta_std:.2g} s (nominal {nominal.damping_beta:.4g})'
        )
    for line in fit.warnings():
        print(f'lumpbeam analyze: warning: {line}', file=sys.stderr)
    if args.json:
        data = fit.as_json()
        data['bags'] = [
            {
                'bag': obs.label,
                'joint_angles_rad': obs.joint_angles_rad.tolist(),
                'modes': [vars(m) for m in obs.sorted_modes()],
            }
            for obs in observations
        ]
        write_json(args.json, data)
    return 0
