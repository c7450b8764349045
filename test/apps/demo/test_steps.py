"""The demo's diagnose step runs the core in-process and gives what `lumpbeam diagnose` gives."""

import json

import pytest

from lumpbeam_ros.apps.cli.main import main
from lumpbeam_ros.apps.demo import run as run_module
from lumpbeam_ros.apps.demo import steps
from lumpbeam_ros.core.model.parameters import load_beam_config
from lumpbeam_ros.core.synthetic.drop_test import SynthOptions, write_drop_test_bag


# One diagnosis each way, about ten seconds of CPU apiece: the end-to-end demo test covers the
# step in the fast suite; this one pins it to the command's output.
@pytest.mark.slow
def test_diagnose_step_matches_the_command(tmp_path, capsys):
    beam, drop = load_beam_config(None)
    bag = tmp_path / 'bag'
    write_drop_test_bag(
        bag,
        beam,
        drop,
        SynthOptions(duration_s=6.0, markers_rate_hz=0.0, effects=run_module.HIDDEN_EFFECT),
    )
    run = run_module.DemoRun(
        options=run_module.DemoOptions(out=tmp_path / 'out'),
        beam=beam,
        drop=drop,
        echo=lambda _line: None,
        normalized_bag=bag,
    )
    steps.diagnose(run)
    written = json.loads((tmp_path / 'out' / 'diagnosis.json').read_text())
    assert written == run.diagnosis
    assert any((tmp_path / 'out' / 'figures').glob('*.png'))
    assert main(['diagnose', str(bag), '--json', str(tmp_path / 'cli.json')]) == 0
    capsys.readouterr()
    assert json.loads((tmp_path / 'cli.json').read_text()) == written
    # The 15 ms latency hidden in the bag is what both name.
    assert written['missing_effect'] == 'sensor_latency'
