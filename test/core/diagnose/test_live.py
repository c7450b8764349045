"""The live workflow's core: stretches from a stream, the record, the published status."""

import dataclasses
import math
from types import SimpleNamespace

import numpy as np
import pytest

from lumpbeam_ros.base.errors import LumpbeamError
from lumpbeam_ros.core.bagio.tipseries import SampleCounts
from lumpbeam_ros.core.diagnose.live import (
    ERROR,
    OK,
    WARN,
    LiveBuffer,
    LiveDiagnosis,
    LiveDiagnosisConfig,
    Stretch,
    diagnose_live,
    named_effects,
    status_values,
)
from lumpbeam_ros.core.diagnose.measurement import make_record
from lumpbeam_ros.core.model.parameters import load_beam_config
from lumpbeam_ros.core.synthetic.drop_test import SynthOptions, simulate_experiment

RELEASE_S = 2.0


def _stream(duration_s=4.5, effects=None, seed=0):
    beam, drop = load_beam_config()
    measured, _ = simulate_experiment(
        beam, drop, SynthOptions(duration_s=duration_s, effects=effects or {})
    )
    rng = np.random.default_rng(seed)
    noise = 20e-6 * rng.standard_normal((2, len(measured)))
    return beam, drop, measured.t, measured.z + noise[0], measured.pitch + noise[1]


def _filled(settings, t, z, pitch, loads=((0.0, 4.5), (RELEASE_S, 0.0)), found=None):
    buffer = LiveBuffer(settings)
    pending = list(loads)
    for ti, zi, pi in zip(t, z, pitch, strict=True):
        while pending and pending[0][0] <= ti:
            buffer.push_load(*pending.pop(0))
        buffer.push_measured(float(ti), float(zi), float(pi))
        if found is not None:  # polled after every pose, as the node's timer does
            stretch = buffer.next_stretch()
            if stretch is not None:
                found.append(stretch)
    return buffer


def test_a_ring_down_is_complete_after_decay_s_and_handed_out_once():
    _, drop, t, z, pitch = _stream()
    settings = LiveDiagnosisConfig(pre_release_s=1.0, decay_s=2.3)
    early = t < RELEASE_S + 2.0
    buffer = _filled(settings, t[early], z[early], pitch[early])
    assert buffer.next_stretch() is None  # the decay has lasted 2 s only
    buffer = _filled(settings, t, z, pitch)
    stretch = buffer.next_stretch()
    assert stretch == Stretch(RELEASE_S - 1.0, RELEASE_S + 2.3, RELEASE_S)
    assert buffer.next_stretch() is None
    record = buffer.record(stretch)
    keep = (t >= 1.0) & (t <= RELEASE_S + 2.3)
    expected = make_record(t[keep], z[keep], pitch[keep], drop.load_kg, [(RELEASE_S, 0.0)])
    assert np.array_equal(record.t, expected.t) and np.array_equal(record.z, expected.z)
    assert record.initial_load_kg == 4.5 and record.load_events == ((RELEASE_S, 0.0),)


def test_a_ring_down_ends_early_once_the_swing_is_small():
    _, _, t, z, pitch = _stream(duration_s=6.0)
    # Above the whole swing: complete as soon as enough poses follow the release.
    found = []
    _filled(LiveDiagnosisConfig(decay_s=60.0, min_amplitude_m=0.5), t, z, pitch, found=found)
    assert len(found) == 1 and 2.0 <= found[0].end_s - RELEASE_S < 2.1
    never = []
    _filled(LiveDiagnosisConfig(decay_s=60.0, min_amplitude_m=1e-6), t, z, pitch, found=never)
    assert never == []


def test_a_window_without_a_release_is_refused_with_a_reason():
    _, _, t, z, pitch = _stream()
    buffer = _filled(LiveDiagnosisConfig(trigger='window', window_s=1.5), t, z, pitch)
    stretch = buffer.next_stretch()
    assert stretch.start_s == t[0] and math.isnan(stretch.release_s)
    with pytest.raises(LumpbeamError, match='no load change between'):
        buffer.record(stretch)
    second = buffer.next_stretch()  # the next window holds the release
    assert second.start_s == stretch.end_s and second.release_s == RELEASE_S


def test_missing_input_names_what_is_missing():
    buffer = LiveBuffer(LiveDiagnosisConfig())
    assert buffer.missing_input().startswith('/tip_pose: no measured pose received yet')
    buffer.push_predicted(1.0, 0.0, 0.0)
    assert 'only /tip_pose_predicted arrives' in buffer.missing_input()
    buffer.push_measured(1.0, 0.0, 0.0)
    assert buffer.missing_input().startswith('/tip_load')
    buffer.push_load(0.5, 4.5)
    assert buffer.missing_input() is None


def test_prediction_gap_is_the_rms_of_measured_minus_predicted():
    buffer = LiveBuffer(LiveDiagnosisConfig())
    t = np.arange(0.0, 3.0, 1 / 180)
    for ti in t:
        buffer.push_measured(ti, 1e-3 * math.sin(10 * ti), 0.0)
        buffer.push_predicted(ti, 1e-3 * math.sin(10 * ti) + 2e-4, 0.0)
    assert buffer.prediction_gap(0.5, 2.5) == pytest.approx(2e-4, rel=1e-9)
    assert math.isnan(buffer.prediction_gap(5.0, 6.0))  # no prediction there


def _result(name, effects=(), before=3e-3, after=2e-5):
    return LiveDiagnosis(name, tuple(effects), before, after, 'why', Stretch(1.0, 4.3, 2.0))


@pytest.mark.parametrize(
    ('result', 'level', 'names'),
    [
        (_result('none'), OK, 'none'),
        (_result('sensor_latency', [('sensor_latency', {'latency_s': 0.015})]), WARN,
         'sensor_latency'),
        (_result('base_compliance', [('base_compliance', {'k_base_nm_per_rad': 2e4}),
                                     ('quadratic_drag', {'c_q': 0.5})]), WARN,
         'base_compliance,quadratic_drag'),
        (_result('unexplained', before=3e-3, after=3e-3), ERROR, 'unexplained'),
    ],
)  # fmt: skip
def test_status_levels_and_keys(result, level, names):
    got, message, pairs = status_values(result)
    values = dict(pairs)
    assert got == level and values['missing_effects'] == names
    assert values['missing_effect'] == result.missing_effect
    assert float(values['gap_before_rms_m']) == result.gap_before_rms_m
    assert values['gap_after_rms_m'] == repr(result.gap_after_rms_m)
    for key, value in result.effect_parameters.items():
        assert values[key] == repr(value) and key in message


def test_simulator_parameters_are_the_effects_contract_names():
    result = _result(
        'sensor_latency',
        [
            ('sensor_latency', {'latency_s': 0.015}),
            ('base_compliance', {'k_base_nm_per_rad': math.inf}),
        ],
    )
    assert result.simulator_parameters() == {'effects.sensor_latency.latency_s': 0.015}


def test_named_effects_reads_a_list_or_the_single_effect():
    single = SimpleNamespace(missing_effect='added_mass', effect_parameters={'mass_kg': 0.3})
    assert named_effects(single) == (('added_mass', {'mass_kg': 0.3}),)
    assert named_effects(SimpleNamespace(missing_effect='none', effect_parameters={})) == ()
    listed = SimpleNamespace(
        missing_effect='added_mass',
        effect_parameters={'mass_kg': 0.3},
        missing_effects=[
            {'name': 'added_mass', 'parameters': {'mass_kg': 0.3}, 'gap_reduction': 0.9},
            SimpleNamespace(name='sensor_scale', parameters={'scale': 1.05}),
        ],
    )
    assert named_effects(listed) == (
        ('added_mass', {'mass_kg': 0.3}),
        ('sensor_scale', {'scale': 1.05}),
    )


def test_diagnose_live_names_a_hidden_latency_on_a_short_ring_down():
    beam, _, t, z, pitch = _stream(effects={'sensor_latency': 0.015})
    buffer = _filled(LiveDiagnosisConfig(decay_s=2.3), t, z, pitch)
    stretch = buffer.next_stretch()
    result = diagnose_live(buffer.record(stretch), beam, stretch)
    assert result.missing_effect == 'sensor_latency'
    assert result.effect_parameters['latency_s'] == pytest.approx(0.015, rel=0.05)
    assert result.gap_after_rms_m < 0.05 * result.gap_before_rms_m


@pytest.mark.parametrize(('name', 'level'), [('none', WARN), ('unexplained', ERROR)])
def test_a_stretch_with_many_poses_dropped_is_never_ok(name, level):
    dropped = SampleCounts(received=2000, duplicates=900)
    result = dataclasses.replace(_result(name), samples=dropped)
    got, message, _ = status_values(result)
    assert got == level
    assert message.endswith('; /tip_pose: dropped 900 of 2000 poses (900 with a repeated or '
                            'out-of-order stamp) in the stretch')  # fmt: skip


def test_late_and_repeated_poses_are_counted_in_the_stretch_record():
    _, _, t, z, pitch = _stream()
    buffer = LiveBuffer(LiveDiagnosisConfig(pre_release_s=1.0, decay_s=2.3))
    buffer.push_load(0.0, 4.5)
    for ti, zi, pi in zip(t, z, pitch, strict=True):
        if ti >= RELEASE_S and buffer.loads[-1][1] != 0.0:
            buffer.push_load(float(ti), 0.0)
        assert buffer.push_measured(float(ti), float(zi), float(pi))
        assert not buffer.push_measured(float(ti) - 0.1, float(zi), float(pi))  # a late stream
    record = buffer.record(buffer.next_stretch())
    assert record.counts.duplicates == len(record) and record.counts.untrusted
    assert buffer.measured.counts.out_of_order == t.size


def _played(
    settings, t, z, pitch, *, passes=1, clock_ahead_s=0.0, odd=None, late_s=None, readings=False
):
    """Plays the stream as a player does, ``passes`` times (a looping bag), polled per pose.

    The loads are sent at their stamps on the node's clock, ``clock_ahead_s`` after the
    poses' time line (0: /clock; a bag played on wall time: its age); ``odd`` is one
    ``(index, stamp)`` pose of a corrupt stamp sent in each pass; ``late_s(i)`` how late the
    player sends message ``i`` (the load: ``-1``). With ``readings``, the load is read every
    second, as a synthetic bag holds it, and once more after the last pose.
    """
    buffer, found = LiveBuffer(settings), []
    for _ in range(passes):
        pending = [(0.0, 4.5), (RELEASE_S, 0.0)]
        if readings:
            pending = [(float(s), 4.5 if s < RELEASE_S else 0.0) for s in range(int(t[-1]) + 1)]
        for i, (ti, zi, pi) in enumerate(zip(t, z, pitch, strict=True)):
            clock_s = float(ti) + clock_ahead_s + (late_s(i) if late_s else 0.0)
            while pending and pending[0][0] <= ti:
                when, kg = pending.pop(0)
                buffer.push_load(when + clock_ahead_s + (late_s(-1) if late_s else 0.0), kg)
            if odd is not None and i == odd[0]:
                buffer.push_measured(odd[1], 1.0, 0.0, sent_s=clock_s)
            buffer.push_measured(float(ti), float(zi), float(pi), sent_s=clock_s)
            stretch = buffer.next_stretch()
            if stretch is not None:
                found.append((stretch, buffer.record(stretch)))
        if readings:  # sent after the pass's last pose: dated by the next pass's poses
            buffer.push_load(float(t[-1]) + clock_ahead_s + 1e-4, 0.0)
    return buffer, found


SETTINGS = LiveDiagnosisConfig(pre_release_s=1.0, decay_s=2.3)
EXPECTED = Stretch(RELEASE_S - 1.0, RELEASE_S + 2.3, RELEASE_S)


@pytest.mark.parametrize('clock_ahead_s', [0.0, 3600.0])
def test_a_looping_bag_gives_every_pass_its_ring_down(clock_ahead_s):
    _, _, t, z, pitch = _stream()
    buffer, found = _played(
        SETTINGS, t, z, pitch, passes=5, clock_ahead_s=clock_ahead_s, readings=True
    )
    # Dated through the poses (a bag on wall time): exact here, one pose's spacing uncertain.
    uncertainty = 0.0 if clock_ahead_s == 0.0 else pytest.approx(1 / 180)
    expected = dataclasses.replace(EXPECTED, release_uncertainty_s=uncertainty)
    assert [stretch for stretch, _ in found] == [expected] * 5
    assert buffer.measured.counts.resets == 4
    assert all(r.initial_load_kg == 4.5 and r.load_events == ((2.0, 0.0),) for _, r in found)
    assert all(np.array_equal(r.z, found[0][1].z) for _, r in found)


@pytest.mark.parametrize('stamp', [RELEASE_S + 1.0 + 163.0, -1e6, 1e12])
def test_one_stamp_far_off_during_a_ring_down_loses_nothing(stamp):
    _, _, t, z, pitch = _stream()
    index = int(np.searchsorted(t, RELEASE_S + 1.0))
    buffer, found = _played(SETTINGS, t, z, pitch, odd=(index, stamp))
    _, clean = _played(SETTINGS, t, z, pitch)
    assert [stretch for stretch, _ in found] == [EXPECTED]
    assert np.array_equal(found[0][1].z, clean[0][1].z)
    assert buffer.measured.counts.out_of_order == 1 and buffer.measured.counts.resets == 0


@pytest.mark.parametrize('ahead_s', [0.004, 86400.0 * 365, -3600.0])
def test_loads_are_dated_on_the_poses_time_line_whatever_the_clock(ahead_s):
    # A bag played on wall time: the node's clock is the bag's age ahead of the stamps.
    _, _, t, z, pitch = _stream()
    _, found = _played(SETTINGS, t, z, pitch, clock_ahead_s=ahead_s, passes=2)
    assert len(found) == 2
    for stretch, record in found:
        ((release, kg),) = record.load_events
        assert kg == 0.0
        if abs(ahead_s) < SETTINGS.reset_jump_back_s:  # by the clock: it agrees with the stamps
            assert release == pytest.approx(RELEASE_S + ahead_s, abs=1e-9)
        else:  # at the stamp of the pose sent before it, never later than it was due
            assert RELEASE_S - stretch.release_uncertainty_s <= release <= RELEASE_S
            assert stretch.release_uncertainty_s == pytest.approx(1 / 180, rel=1e-6)
        assert stretch.release_s == release


@pytest.mark.parametrize('late_load_s', [0.0, 0.039])
def test_a_release_played_by_a_late_player_is_dated_by_the_poses_sent_around_it(late_load_s):
    _, _, t, z, pitch = _stream()
    lateness = np.random.default_rng(1).uniform(0.0, 3e-3, t.size)
    # A player that stalls before the load is late for it and for the poses after it.
    lateness[t >= RELEASE_S] += late_load_s

    def late_s(i):
        return lateness[i] if i >= 0 else 3e-3 + late_load_s

    _, found = _played(SETTINGS, t, z, pitch, clock_ahead_s=3600.0, late_s=late_s)
    ((stretch, _),) = found
    early = RELEASE_S - stretch.release_s  # never late: that would be a negative delay
    assert 0.0 <= early <= stretch.release_uncertainty_s == pytest.approx(1 / 180)


@pytest.mark.parametrize(('uncertainty_s', 'verdict'), [(0.0, 'sensor_latency'), (2e-3, 'none')])
def test_a_latency_within_the_release_dating_is_not_named(uncertainty_s, verdict):
    beam, _, t, z, pitch = _stream()
    early = 1e-3  # the release dated a millisecond early: the tip seems to follow late
    loads = ((0.0, 4.5), (RELEASE_S - early, 0.0))
    buffer = _filled(LiveDiagnosisConfig(decay_s=2.3), t, z, pitch, loads=loads)
    stretch = dataclasses.replace(buffer.next_stretch(), release_uncertainty_s=uncertainty_s)
    result = diagnose_live(buffer.record(stretch), beam, stretch)
    assert result.missing_effect == verdict
    if verdict == 'none':
        assert result.reason.startswith('the delay found, 1.0') and 'no stamp' in result.reason


@pytest.mark.parametrize('load_sent_s', [-1e-4, 1e-4], ids=['before-its-pose', 'after-it'])
def test_a_latency_past_the_dating_is_named_less_the_releases_lead(load_sent_s):
    """A player sends the release a hair before or after the pose of the same stamp.

    Sent before, the release is dated a pose's spacing early: the workflow's delay is
    then the sensor's 15 ms plus 5.6 ms, the lead its send time gives back.
    """
    beam, _, t, z, pitch = _stream(effects={'sensor_latency': 0.015})

    def late_s(i):
        return load_sent_s if i < 0 else 0.0

    _, found = _played(SETTINGS, t, z, pitch, clock_ahead_s=3600.0, late_s=late_s)
    ((stretch, record),) = found
    early = RELEASE_S - stretch.release_s
    assert early == pytest.approx(1 / 180 if load_sent_s < 0 else 0.0, abs=1e-9)
    assert stretch.release_lead_s == pytest.approx(early, abs=2e-4)
    result = diagnose_live(record, beam, stretch)
    assert result.missing_effect == 'sensor_latency'
    ((name, parameters),) = result.missing_effects
    assert parameters['latency_s'] == pytest.approx(0.015, abs=2e-4)


def test_a_load_delivered_ahead_of_a_backlog_of_poses_is_dated_when_they_arrive():
    _, _, t, z, pitch = _stream()
    buffer = LiveBuffer(SETTINGS)
    buffer.push_load(-1.0, 4.5)  # before any pose: what hangs from the start
    backlog = t >= RELEASE_S - 0.05  # these poses are still on their way
    for ti, zi, pi in zip(t[~backlog], z[~backlog], pitch[~backlog], strict=True):
        buffer.push_measured(float(ti), float(zi), float(pi), sent_s=3600.0 + ti)
    buffer.push_load(3600.0 + RELEASE_S - 1e-4, 0.0)  # sent just before the pose at 2.0 s
    assert buffer.loads == [(-math.inf, 4.5)]  # not dated yet
    for ti, zi, pi in zip(t[backlog], z[backlog], pitch[backlog], strict=True):
        buffer.push_measured(float(ti), float(zi), float(pi), sent_s=3600.0 + ti)
    release = buffer.loads[-1][0]
    assert release == pytest.approx(RELEASE_S - 1 / 180) and buffer.next_stretch() is not None
