"""Arms shared by the arm's tests: the paper's beam as a one-link arm and small test arms."""

import numpy as np

from lumpbeam_lab.mujoco_arm import beam_as_arm
from lumpbeam_ros.core.ident.arm.link_fit import MeasuredMode, ModeObservation
from lumpbeam_ros.core.model.arm.config import ArmConfig, arm_from_mapping
from lumpbeam_ros.core.model.arm.drive import SmoothMotion
from lumpbeam_ros.core.model.arm.joint_trajectory import JointTrajectory
from lumpbeam_ros.core.model.arm.model import ArmModel
from lumpbeam_ros.core.model.arm.statics import arm_modes
from lumpbeam_ros.core.model.parameters import BeamParameters


def paper_beam_arm(beam: BeamParameters) -> ArmConfig:
    """The identified paper beam (mounted mass at the free end) as a one-link arm."""
    return beam_as_arm(beam)


def small_arm(n_links: int, plane: str = 'vertical') -> ArmConfig:
    """A light arm of 1 to 3 links with few segments (fast to simulate), unequal links."""
    return arm_from_mapping(small_arm_document(n_links, plane), 'small')


def small_arm_document(n_links: int, plane: str = 'vertical') -> dict:
    """:func:`small_arm` as the mapping of its arm file."""
    links = [
        {'length_m': 1.0, 'n_segments': 4, 'ei_nm2': 500.0, 'mass_kg': 1.0, 'damping_beta': 1e-3},
        {
            'length_m': 0.7,
            'n_segments': 3,
            'ei_nm2': [400.0, 300.0, 200.0],
            'mass_kg': 0.5,
            'damping_beta': 1.5e-3,
            'joint_mass_kg': 0.8,
        },
        {
            'length_m': 0.5,
            'n_segments': 3,
            'k_total_nm_per_rad': 250.0,
            'mass_kg': [0.15, 0.1, 0.05],
            'damping_beta': 2e-3,
            'joint_mass_kg': 0.4,
        },
    ]
    return {'arm': {'plane': plane, 'payload_kg': 0.3, 'links': links[:n_links]}}


def smooth_move(amplitude: np.ndarray, duration: float) -> SmoothMotion:
    """A rest-to-rest cycloidal move of every joint by ``amplitude`` over ``duration``."""
    amplitude = np.asarray(amplitude, dtype=float)

    def angles(t: float) -> np.ndarray:
        s = min(max(t / duration, 0.0), 1.0)
        return amplitude * (s - np.sin(2 * np.pi * s) / (2 * np.pi))

    def rates(t: float) -> np.ndarray:
        s = min(max(t / duration, 0.0), 1.0)
        return amplitude * (1 - np.cos(2 * np.pi * s)) / duration

    return SmoothMotion(angles, rates, amplitude.size, duration)


def write_move_bag(out, arm: ArmConfig, final, move_s=0.5, record_s=4.0, names=()):
    """A synthetic bag of the arm moved from 0 to ``final`` (minimum jerk) and left to ring.

    Returns:
        ``out``.
    """
    from lumpbeam_ros.core.model.arm.joint_trajectory import JointTrajectory
    from lumpbeam_ros.core.synthetic.arm_bag import ArmSynthOptions, write_arm_bag

    t = np.linspace(0.0, move_s, int(round(move_s * 1000)) + 1)
    s = t / move_s
    s = 10 * s**3 - 15 * s**4 + 6 * s**5
    trajectory = JointTrajectory(t, np.outer(s, np.asarray(final, dtype=float)), tuple(names))
    write_arm_bag(out, arm, trajectory, ArmSynthOptions(duration_s=record_s))
    return out


#: Final joint angles of the moves (the vertical arm's modes change with them).
FINALS = ([0.3, -0.4, 0.5], [-0.4, 0.6, -0.3], [0.6, 0.2, 0.4], [-0.2, -0.7, 0.9])
#: Relative standard deviations of the measured frequencies and damping ratios, mode k
#: (1-based) times these: the contract's accuracy of multi-mode identification.
F_REL, ZETA_REL = 1e-3, 0.05


def observe_modes(truth, finals, n_modes, rng=None, modes_at=None):
    """The truth's first ``n_modes`` at each final configuration, noisy when ``rng`` is given."""
    model = ArmModel.from_config(truth)
    out = []
    for q in finals:
        q = np.asarray(q, dtype=float)
        f, zeta = modes_at(q) if modes_at else modes_of(model, q)
        measured = []
        for k in range(n_modes):
            f_std, z_std = F_REL * (k + 1) * f[k], ZETA_REL * (k + 1) * zeta[k]
            df, dz = (f_std, z_std) * rng.standard_normal(2) if rng is not None else (0.0, 0.0)
            measured.append(MeasuredMode(f[k] + df, f_std, zeta[k] + dz, z_std))
        out.append(ModeObservation(q, tuple(measured), f'q={q.tolist()}'))
    return out


def modes_of(model, q):
    """The model's frequencies and damping ratios at rest at q."""
    modes = arm_modes(model, q)
    return modes.natural_frequency_hz, modes.damping_ratio


def minimum_jerk(start, end, duration, before=0.0, after=0.0, step=1e-3):
    """A rest-to-rest move sampled every ``step``, with rests before and after it."""
    t = np.arange(round((before + duration + after) / step) + 1) * step
    s = np.clip((t - before) / duration, 0.0, 1.0)
    path = 10 * s**3 - 15 * s**4 + 6 * s**5
    start, end = np.asarray(start, dtype=float), np.asarray(end, dtype=float)
    return JointTrajectory(t, start + np.outer(path, end - start))
