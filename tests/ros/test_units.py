import pytest

from rrtpso_ompl.errors import ProblemError
from rrtpso_ompl.ros.units import metres_per_unit


@pytest.mark.parametrize(
    ("units", "metres"),
    [("mm", 1e-3), ("cm", 1e-2), ("m", 1.0), ("", 1.0), (" Metres ", 1.0), ("ft", 0.3048)],
)
def test_known_units_convert_to_metres(units, metres):
    assert metres_per_unit(units) == metres


def test_an_unknown_unit_names_the_file_and_the_key():
    with pytest.raises(ProblemError) as err:
        metres_per_unit("furlong", "world.yaml")
    assert str(err.value).startswith("world.yaml: units: unknown length unit 'furlong'")
