from lumpbeam_ros.nodes.counts import COUNTS_DIR_ENV, read_counts, write_counts


def test_counts_are_written_only_when_asked_and_read_back(tmp_path, monkeypatch):
    monkeypatch.delenv(COUNTS_DIR_ENV, raising=False)
    assert write_counts('camera_node', {'/tip_pose': 3}) is None
    monkeypatch.setenv(COUNTS_DIR_ENV, str(tmp_path / 'counts'))
    path = write_counts('camera_node', {'/tip_pose': 3}, {'/camera/image_raw': 4})
    assert path == tmp_path / 'counts' / 'camera_node.json'
    assert write_counts('player', {'/clock': 7})
    (tmp_path / 'counts' / 'broken.json').write_text('{not json')
    assert read_counts(tmp_path / 'counts') == {
        'camera_node': {'published': {'/tip_pose': 3}, 'received': {'/camera/image_raw': 4}},
        'player': {'published': {'/clock': 7}, 'received': {}},
    }


def test_an_unwritable_folder_never_fails_the_node(tmp_path, monkeypatch):
    (tmp_path / 'file').write_text('x')
    monkeypatch.setenv(COUNTS_DIR_ENV, str(tmp_path / 'file'))
    assert write_counts('camera_node', {'/tip_pose': 1}) is None
