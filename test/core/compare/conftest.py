import pytest

from .helpers import Pair, make_pair


@pytest.fixture(scope='package')
def pair() -> Pair:
    """The default camera and tracker (7.3 ms offset, 3 m away, rotated), 6 s."""
    return make_pair()
