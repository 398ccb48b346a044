import math

import numpy as np
import pytest

from synergrasp.config import defaults
from synergrasp.figures.hand_figures import Fig2Params
from synergrasp.optimisation.study import OptimiseParams
from synergrasp.simulation.objects import Box, ObjectError


def test_study_boxes_from_the_config_defaults():
    boxes = Fig2Params.from_config(defaults()).boxes
    assert [b.name for b in boxes] == ["obj1", "obj2", "obj3", "obj4"]
    np.testing.assert_array_equal(boxes[3].size_mm, [100, 60, 100])
    np.testing.assert_array_equal(boxes[1].half_extents_mm, [15, 30, 30])
    assert all(b.mass_kg is None for b in boxes)  # Fig. 2 does not read the masses
    assert all(OptimiseParams.from_config(defaults(), b.name).gfo.mass_kg == 1.0 for b in boxes)
    assert Box("a", [1, 2, 3], 1).mass_kg == 1.0 and isinstance(Box("a", [1, 2, 3], 1).mass_kg, float)


def test_size_is_read_only():
    with pytest.raises(ValueError):
        Box("a", [1, 2, 3], 1.0).size_mm[0] = 1.0


def test_mass_may_be_left_out_where_a_step_does_not_read_it():
    assert Box("a", [1, 2, 3]).mass_kg is None


GOOD = {"name": "cube", "size_mm": [10, 20, 30], "mass_kg": 0.5}


@pytest.mark.parametrize("change, match", [
    ({"size_mm": [10, 0, 30]}, "object 'cube': field 'size_mm'"),
    ({"size_mm": [10, -1, 30]}, "field 'size_mm'"),
    ({"size_mm": [10, math.inf, 30]}, "field 'size_mm'"),
    ({"size_mm": [10, math.nan, 30]}, "field 'size_mm'"),
    ({"size_mm": [10, 20]}, "field 'size_mm'"),
    ({"size_mm": 10}, "field 'size_mm'"),
    ({"size_mm": ["a", 1, 2]}, "field 'size_mm'"),
    ({"mass_kg": 0}, "object 'cube': field 'mass_kg'"),
    ({"mass_kg": -1.0}, "field 'mass_kg'"),
    ({"mass_kg": math.nan}, "field 'mass_kg'"),
    ({"mass_kg": "heavy"}, "field 'mass_kg'"),
    ({"name": "my box"}, r"\[A-Za-z0-9_\]\+"),
    ({"name": "../x"}, "field 'name'"),
    ({"name": ""}, "field 'name'"),
])
def test_bad_entries_raise_one_clear_error(change, match):
    with pytest.raises(ObjectError, match=match):
        Box(**{**GOOD, **change})


def test_box_constructor_validates_too():
    with pytest.raises(ObjectError, match="size_mm"):
        Box("b", [1, 2, 3, 4], 1.0)
