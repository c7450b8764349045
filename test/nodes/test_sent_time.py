import pytest

from lumpbeam_ros.nodes.sent_time import MAX_DELAY_S, SentClock, sent_ns

NOW_S = 1_700_000_000.0
NOW_NS = round(NOW_S * 1e9)


@pytest.mark.parametrize(
    ('info', 'expected'),
    [({'source_timestamp': 5, 'received_timestamp': 7}, 5), ({}, 0), (None, 0)],
)
def test_sent_ns_reads_the_source_timestamp(info, expected):
    assert sent_ns(info) == expected


@pytest.mark.parametrize(
    ('sent', 'expected'),
    [
        (0, NOW_S),  # unknown
        (NOW_NS - 30_000_000, NOW_S - 0.03),  # delivered 30 ms late
        (NOW_NS + 1_000_000_000, NOW_S),  # after now: another host's clock
        (NOW_NS - round((MAX_DELAY_S + 1) * 1e9), NOW_S),  # far back: another host's clock
    ],
)
def test_on_wall_time_a_message_is_dated_by_its_send_time(sent, expected):
    assert SentClock(sim_time=False).sent_at(sent, NOW_S) == pytest.approx(expected, abs=1e-6)


@pytest.mark.parametrize(
    ('sent', 'now_s', 'expected'),
    [
        (0, 12.0, 12.0),  # unknown
        (500, 12.0, 12.0),  # before every /clock kept
        (1000, 12.0, 10.0),
        (1999, 12.0, 10.0),  # sent between two /clock samples: the earlier one's time
        (2000, 12.0, 10.5),
        (9999, 12.0, 11.0),  # after the newest
        (9999, 10.8, 10.8),  # never after now
        (9999, 11.0 + MAX_DELAY_S + 1, 11.0 + MAX_DELAY_S + 1),  # too far back: now
    ],
)
def test_on_sim_time_a_message_is_dated_by_the_clock_sent_before_it(sent, now_s, expected):
    clock = SentClock(sim_time=True)
    for clock_sent, clock_s in [(1000, 10.0), (2000, 10.5), (1500, 99.0), (3000, 11.0)]:
        clock.clock_sent(clock_sent, clock_s)  # the one sent out of order is left out
    assert clock.sent_at(sent, now_s) == expected


def test_without_any_clock_a_message_is_dated_now():
    assert SentClock(sim_time=True).sent_at(NOW_NS, 3.0) == 3.0
