"""The simulator node's parameters (values in ``config/simulator.yaml``, documented there)."""

from __future__ import annotations

from lumpbeam_ros.base.interface import (
    JOINT_TRAJECTORY,
    JOINT_TRAJECTORY_SHAPED,
    MARKERS_RATE_HZ,
    POSE_RATE_HZ,
    SIMULATOR_NODE,
)
from lumpbeam_ros.base.schema import Bounds, ParameterSchema, ParameterSpec
from lumpbeam_ros.core.model.parameters import EFFECTS, EffectRecord


def effect_parameter_name(effect: str) -> str:
    """The simulator's parameter of an effect: ``effects.<effect>.<contract parameter>``."""
    return EFFECTS[effect].key


def _effect_spec(record: EffectRecord) -> ParameterSpec:
    return ParameterSpec(
        effect_parameter_name(record.name),
        'double',
        record.off,
        f'{record.meaning}: the {record.name} effect the beam runs with (as in the beam file, '
        'whose value it takes at start unless given); set at run time, the beam keeps its '
        'motion',
        record.unit,
        record.limits,
        read_only=False,
    )


SIMULATOR_SCHEMA = ParameterSchema(
    node=SIMULATOR_NODE,
    summary=(
        'The lumped beam run in step with the node clock, publishing the predicted tip pose; '
        'or, with an arm file, the flexible arm following its joint commands. Every parameter '
        'but the arm ones can be changed while it runs (`ros2 param set`).'
    ),
    config_file='simulator.yaml',
    parameters=(
        ParameterSpec(
            'beam_config',
            'string',
            '',
            "beam parameter file (as config/paper_beam.yaml); empty: the package's "
            'paper_beam.yaml. Setting it at run time swaps the beam and keeps the motion',
            read_only=False,
        ),
        ParameterSpec(
            'rate_hz',
            'double',
            POSE_RATE_HZ,
            'rate of /tip_pose_predicted; samples are stamped k / rate_hz',
            'Hz',
            Bounds(1.0, 2000.0),
            read_only=False,
        ),
        ParameterSpec(
            'tick_rate_hz',
            'double',
            50.0,
            'how often the model is advanced and published',
            'Hz',
            Bounds(1.0, 1000.0),
            read_only=False,
        ),
        ParameterSpec(
            'initial_load_kg',
            'double',
            0.0,
            'load assumed until the first /tip_load',
            'kg',
            Bounds(0.0, 1000.0),
            read_only=False,
        ),
        ParameterSpec(
            'adopt_identified',
            'bool',
            False,
            'adopt k_tE and the damping ratio from /beam_params (status OK only); an arm '
            '(arm_config): its links or payload from /arm_params (status OK only)',
            read_only=False,
        ),
        ParameterSpec(
            'reset_jump_back_s',
            'double',
            0.1,
            'a clock step back beyond this restarts the beam at rest',
            's',
            Bounds(0.0, 3600.0),
            read_only=False,
        ),
        ParameterSpec(
            'max_catch_up_s',
            'double',
            5.0,
            'a clock jump ahead beyond this restarts the beam at rest',
            's',
            Bounds(0.01, 3600.0),
            read_only=False,
        ),
        ParameterSpec(
            'markers_rate_hz',
            'double',
            MARKERS_RATE_HZ,
            'rate of /beam_markers (the beam, its tip, the measured tip, the load, the board), '
            'independent of rate_hz; 0 publishes none',
            'Hz',
            Bounds(0.0, 200.0),
            read_only=False,
        ),
        ParameterSpec(
            'camera_config',
            'string',
            '',
            'camera parameter file whose checkerboard /beam_markers draws; empty: the '
            "package's camera.yaml",
            read_only=False,
        ),
        ParameterSpec(
            'arm_config',
            'string',
            '',
            'arm file (as config/arm_3link.yaml); empty: the clamped beam of beam_config. Given, '
            'the node simulates the arm following its joint commands and publishes /joint_states '
            'too; the beam parameters (loads, effects, adoption) are then unused',
        ),
        ParameterSpec(
            'arm_commands',
            'string',
            JOINT_TRAJECTORY,
            "the arm follows the joint trajectories of this topic: the planner's, or the "
            "shaper node's",
            choices=(JOINT_TRAJECTORY, JOINT_TRAJECTORY_SHAPED),
        ),
        ParameterSpec(
            'arm_ring_down_s',
            'double',
            10.0,
            "each simulation of the arm reaches this far past the last command's end (then "
            'it is extended)',
            's',
            Bounds(0.1, 3600.0),
        ),
        ParameterSpec(
            'arm_history_s',
            'double',
            60.0,
            'a command re-simulates the arm from the last time it was at rest, at most this far '
            'back; beyond it the arm restarts at rest at the held angles',
            's',
            Bounds(1.0, 3600.0),
        ),
        *(_effect_spec(record) for record in EFFECTS.values()),
    ),
)
