import pytest

from lumpbeam_ros.base.closing import ClosedOnExit


class _Held(ClosedOnExit):
    def __init__(self) -> None:
        self.closed = 0

    def close(self) -> None:
        self.closed += 1


def test_the_block_gets_the_object_and_it_is_closed_after():
    with _Held() as held:
        assert isinstance(held, _Held) and held.closed == 0
    assert held.closed == 1


def test_it_is_closed_when_the_block_raises_and_the_error_goes_on():
    held = _Held()
    with pytest.raises(KeyError), held:
        raise KeyError('x')
    assert held.closed == 1


def test_a_class_that_does_not_say_how_to_close_cannot_be_made():
    class _Forgetful(ClosedOnExit):
        pass

    with pytest.raises(TypeError, match='close'):
        _Forgetful()  # type: ignore[abstract]
