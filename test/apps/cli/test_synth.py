"""``lumpbeam synth``: ``--force`` replaces a bag and nothing else; ``--effect none``."""

from lumpbeam_ros.apps.cli.main import main
from lumpbeam_ros.core.bagio import BagReader


def test_force_replaces_a_bag_and_only_a_bag(tmp_path, capsys):
    out = tmp_path / 'drop'
    assert main(['synth', str(out), '--duration', '3']) == 0
    assert main(['synth', str(out), '--duration', '3']) == 2  # a bag is never overwritten...
    assert main(['synth', str(out), '--duration', '4', '--force']) == 0  # ...unless asked
    assert BagReader(out).topics['/tip_pose'].count == 4 * 180 + 1
    folder = tmp_path / 'notes'
    folder.mkdir()
    (folder / 'mine.txt').write_text('keep me')
    capsys.readouterr()
    assert main(['synth', str(folder), '--force']) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and 'is not a bag' in err[0]
    assert (folder / 'mine.txt').read_text() == 'keep me'


def test_effect_none_hides_nothing_and_stands_alone(tmp_path, capsys):
    assert main(['synth', str(tmp_path / 'a'), '--duration', '3', '--effect', 'none']) == 0
    assert 'hidden effects: none' in capsys.readouterr().out
    args = ['synth', str(tmp_path / 'b'), '--effect', 'none', '--effect', 'added_mass=0.1']
    assert main(args) == 2
    assert '--effect none stands alone' in capsys.readouterr().err
