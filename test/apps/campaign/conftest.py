"""Short synthetic campaigns shared by the campaign tests."""

from pathlib import Path

import pytest

from lumpbeam_ros.core.model.parameters import DropTestConfig, load_beam_config
from lumpbeam_ros.core.synthetic.campaign_bags import write_campaign
from lumpbeam_ros.core.synthetic.drop_test import SynthOptions

#: Loads of the shared campaign, kg, one seed each.
LOADS = (1.0, 4.0, 9.0)


def truncate_bag(bag: Path, fraction: float) -> None:
    """Cuts a bag's data file to a fraction of its length, as a recording killed halfway."""
    (mcap,) = bag.glob('*.mcap')
    size = mcap.stat().st_size
    with mcap.open('r+b') as stream:
        stream.truncate(int(size * fraction))


@pytest.fixture(scope='session')
def campaign_bags(tmp_path_factory) -> list[Path]:
    """Three 5 s drop tests at 1, 4 and 9 kg (written once per session; do not modify)."""
    beam, _ = load_beam_config()
    out = tmp_path_factory.mktemp('campaign') / 'bags'
    return write_campaign(
        out, beam, DropTestConfig(duration_s=5.0), SynthOptions(duration_s=5.0), LOADS, 1
    )
