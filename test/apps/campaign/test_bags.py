import shutil

import pytest

from lumpbeam_ros.apps.campaign.bags import bag_facts, expand_bags, fingerprint
from lumpbeam_ros.base.errors import LumpbeamError


def test_paths_and_patterns_expand_to_each_bag_once(campaign_bags):
    folder = campaign_bags[0].parent
    found = expand_bags([str(campaign_bags[1]), str(folder / '*')])
    assert found == [campaign_bags[1], *sorted(b for b in campaign_bags if b != campaign_bags[1])]


@pytest.mark.parametrize(
    ('argument', 'message'),
    [
        ('{tmp}/nothing*', 'matches no file or folder'),
        ('{tmp}/missing', 'no such bag folder'),
        ('{tmp}', 'not a rosbag2 bag'),
    ],
)
def test_bad_arguments_name_the_input(tmp_path, argument, message):
    text = argument.format(tmp=tmp_path)
    with pytest.raises(LumpbeamError, match=message) as info:
        expand_bags([text])
    assert text in str(info.value) and '\n' not in str(info.value)


def test_fingerprint_follows_content_not_place(campaign_bags, tmp_path):
    copy = tmp_path / 'copy'
    shutil.copytree(campaign_bags[0], copy)
    assert fingerprint(copy) == fingerprint(campaign_bags[0])
    assert fingerprint(campaign_bags[0]) != fingerprint(campaign_bags[1])
    (mcap,) = copy.glob('*.mcap')
    data = bytearray(mcap.read_bytes())
    data[len(data) // 2] ^= 0xFF  # one flipped byte in the middle
    mcap.write_bytes(bytes(data))
    assert fingerprint(copy) != fingerprint(campaign_bags[0])


def test_large_files_are_hashed_by_their_edges(campaign_bags, tmp_path, monkeypatch):
    import lumpbeam_ros.apps.campaign.bags as bags

    copy = tmp_path / 'copy'
    shutil.copytree(campaign_bags[0], copy)
    (mcap,) = copy.glob('*.mcap')
    monkeypatch.setattr(bags, 'FULL_HASH_BYTES', 1000)
    monkeypatch.setattr(bags, 'EDGE_BYTES', 100)
    before = fingerprint(copy)
    data = bytearray(mcap.read_bytes())
    data[-1] ^= 0xFF  # the closing summary changes when a bag changes
    mcap.write_bytes(bytes(data))
    assert fingerprint(copy) != before


def test_facts_come_from_the_metadata(campaign_bags):
    facts = bag_facts(campaign_bags[0])
    assert facts.pose_count == 901  # 5 s at 180 Hz, both ends
    assert facts.duration_s == pytest.approx(5.0, abs=0.01)
    assert facts.load_count >= 6 and facts.message_count > 2 * facts.pose_count
    assert facts.start_time.startswith('1970-01-01T00:00:00')
