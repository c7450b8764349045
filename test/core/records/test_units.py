import pytest

from lumpbeam_ros.core.records.to_bag import ImportOptions
from lumpbeam_ros.core.records.units import AXES, STANDARD_GRAVITY, UNITS


@pytest.mark.parametrize('quantity', UNITS)
def test_each_quantity_defaults_to_its_si_unit(quantity):
    assert next(iter(UNITS[quantity].values())) == 1.0
    assert ImportOptions(quantity).factor() == 1.0


@pytest.mark.parametrize(
    ('quantity', 'unit', 'factor'),
    [('displacement', 'mm', 1e-3), ('displacement', 'um', 1e-6), ('acceleration', 'g', 9.80665)],
)
def test_units_convert_to_si(quantity, unit, factor):
    assert ImportOptions(quantity, unit).factor() == factor


def test_standard_gravity_is_the_cgpm_value_and_z_the_default_axis():
    assert STANDARD_GRAVITY == 9.80665  # 3rd CGPM (1901), exact by definition
    assert ImportOptions('displacement').axis == AXES[-1] == 'z'
