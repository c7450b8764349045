import pytest

from lumpbeam_ros.apps.cli.main import main
from lumpbeam_ros.base.errors import LumpbeamError
from lumpbeam_ros.core.bagio import read_load_events
from lumpbeam_ros.core.synthetic.campaign_bags import parse_loads


def test_loads_parse():
    assert parse_loads('0.5, 1,10') == [0.5, 1.0, 10.0]


@pytest.mark.parametrize(
    ('text', 'message'),
    [('1,x', "'x' is not a number"), ('1,-2', 'positive'), ('', 'not a number')],
)
def test_bad_loads_are_one_line(text, message):
    with pytest.raises(LumpbeamError, match=message):
        parse_loads(text)


def test_synth_writes_one_bag_per_load_and_seed(tmp_path, capsys):
    out = tmp_path / 'campaign'
    argv = [
        'synth',
        str(out),
        '--loads',
        '0.5,2',
        '--seeds',
        '2',
        '--duration',
        '3',
        '--seed',
        '7',
    ]
    assert main(argv) == 0
    names = sorted(p.name for p in out.iterdir())
    assert names == [f'load_{m}kg_seed{s}' for m in ('0.5', '2') for s in (7, 8)]
    # Each bag hangs its own load until the release.
    assert read_load_events(out / 'load_2kg_seed8').kg[0] == 2.0
    assert main(argv) == 2 and 'exists' in capsys.readouterr().err
