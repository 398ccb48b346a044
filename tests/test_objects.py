import math

import numpy as np
import pytest

from synergrasp.simulation.objects import STUDY_BOXES, Box, ObjectError, boxes_from_config


def test_study_boxes():
    assert [b.name for b in STUDY_BOXES] == ["obj1", "obj2", "obj3", "obj4"]
    np.testing.assert_array_equal(STUDY_BOXES[3].size_mm, [100, 60, 100])
    np.testing.assert_array_equal(STUDY_BOXES[1].half_extents_mm, [15, 30, 30])
    assert all(b.mass_kg == 1.0 for b in STUDY_BOXES)


def test_from_config_matches_and_ignores_placement():
    boxes = boxes_from_config([{"name": "obj4", "size_mm": [100, 60, 100], "mass_kg": 1,
                                "placement": {"center_mm": [0, 0, 0]}}])
    assert boxes == (STUDY_BOXES[3],)
    assert isinstance(boxes[0].mass_kg, float)


def test_size_is_read_only():
    with pytest.raises(ValueError):
        STUDY_BOXES[0].size_mm[0] = 1.0


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
    ({"colour": "red"}, r"unknown fields \['colour'\]"),
])
def test_bad_entries_raise_one_clear_error(change, match):
    with pytest.raises(ObjectError, match=match):
        boxes_from_config([{**GOOD, **change}])


def test_missing_field_and_duplicates():
    with pytest.raises(ObjectError, match=r"missing fields \['mass_kg'\]"):
        boxes_from_config([{"name": "a", "size_mm": [1, 1, 1]}])
    with pytest.raises(ObjectError, match="object 'cube': field 'name' is duplicated"):
        boxes_from_config([GOOD, dict(GOOD)])


def test_box_constructor_validates_too():
    with pytest.raises(ObjectError, match="size_mm"):
        Box("b", [1, 2, 3, 4], 1.0)
