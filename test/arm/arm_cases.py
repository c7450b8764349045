"""Arms shared by the arm's tests: the paper's beam as a one-link arm and small test arms."""

import numpy as np

from lumpbeam_ros.arm.config import ArmConfig, arm_from_mapping
from lumpbeam_ros.arm.drive import SmoothMotion
from lumpbeam_ros.model.parameters import BeamParameters

#: The identified beam's damping as a spring-by-spring beta: c_E / k_E (B.13, B.23).
PAPER_BETA = 12 * 0.08 / 3899.1


def paper_beam_arm(beam: BeamParameters) -> ArmConfig:
    """The identified paper beam (mounted mass at the free end) as a one-link arm."""
    link = {
        'length_m': beam.length_m,
        'n_segments': beam.n_segments,
        'k_total_nm_per_rad': beam.k_total_nm_per_rad,
        'mass_kg': beam.mass_kg,
        'damping_beta': beam.beta_identified * beam.c_total / beam.k_total_nm_per_rad,
    }
    return arm_from_mapping({'arm': {'payload_kg': beam.tip_mass_kg, 'links': [link]}}, 'paper')


def small_arm(n_links: int, plane: str = 'vertical') -> ArmConfig:
    """A light arm of 1 to 3 links with few segments (fast to simulate), unequal links."""
    return arm_from_mapping(small_arm_document(n_links, plane), 'small')


def small_arm_document(n_links: int, plane: str = 'vertical') -> dict:
    """The arm file of :func:`small_arm`, as parsed YAML."""
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
