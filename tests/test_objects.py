import math

import numpy as np
import pytest

from synergrasp.config import defaults
from synergrasp.figures.grasp_3d import Grasps3dParams
from synergrasp.optimisation.optimise import OptimiseParams
from synergrasp.simulation.objects import GraspedObject, ObjectError
from synergrasp.simulation.shapes import Box, ShapeError, shape_from_config


def test_study_objects_from_the_config_defaults():
    objects = Grasps3dParams.from_config(defaults()).objects
    assert [o.name for o in objects] == ["obj1", "obj2", "obj3", "obj4"]
    assert all(o.shape.kind == "box" for o in objects)
    assert objects[3].shape.size_mm == (100.0, 60.0, 100.0)
    np.testing.assert_array_equal(objects[1].shape.half_extents_mm, [15, 30, 30])
    assert all(o.mass_kg is None for o in objects)  # Fig. 2 does not read the masses
    assert all(OptimiseParams.from_config(defaults(), o.name).gfo.weight_N == 9.81 for o in objects)
    heavy = GraspedObject("a", Box((1, 2, 3)), 1)
    assert heavy.mass_kg == 1.0 and isinstance(heavy.mass_kg, float)


def test_half_extents_are_read_only():
    with pytest.raises(ValueError):
        Box((1, 2, 3)).half_extents_mm[0] = 1.0


def test_mass_may_be_left_out_where_a_step_does_not_read_it():
    assert GraspedObject("a", Box((1, 2, 3))).mass_kg is None


@pytest.mark.parametrize(
    "change, match",
    [
        ({"mass_kg": 0}, "object 'cube': field 'mass_kg'"),
        ({"mass_kg": -1.0}, "field 'mass_kg'"),
        ({"mass_kg": math.nan}, "field 'mass_kg'"),
        ({"mass_kg": "heavy"}, "field 'mass_kg'"),
        ({"name": "my box"}, r"\[A-Za-z0-9_\]\+"),
        ({"name": "../x"}, "field 'name'"),
        ({"name": ""}, "field 'name'"),
        ({"shape": (10, 20, 30)}, "field 'shape'"),
    ],
)
def test_bad_objects_raise_one_clear_error(change, match):
    with pytest.raises(ObjectError, match=match):
        GraspedObject(**{"name": "cube", "shape": Box((10, 20, 30)), "mass_kg": 0.5, **change})


@pytest.mark.parametrize(
    "spec, match",
    [
        ({"box": {"size_mm": [10, 0, 30]}}, r"'s\.box\.size_mm': \[10, 0, 30\] is not allowed"),
        ({"box": {"size_mm": [10, -1, 30]}}, "'s.box.size_mm'"),
        ({"box": {"size_mm": [10, math.inf, 30]}}, "'s.box.size_mm'"),
        ({"box": {"size_mm": [10, math.nan, 30]}}, "'s.box.size_mm'"),
        ({"box": {"size_mm": [10, 20]}}, "'s.box.size_mm'"),
        ({"box": {"size_mm": 10}}, "'s.box.size_mm'"),
        ({"box": {"size_mm": ["a", 1, 2]}}, "'s.box.size_mm'"),
        ({"box": {"size_mm": "abc"}}, "'s.box.size_mm'"),
        ({"box": {"size": [1, 2, 3]}}, r"'s\.box': .*size"),
        ({"cone": {"size_mm": [1, 2, 3]}}, r"'s': unknown shape 'cone'; allowed: \['box'"),
        ({"box": {"size_mm": [1, 2, 3]}, "sphere": {}}, "'s': one of"),
        ([1, 2, 3], "'s': one of"),
    ],
)
def test_bad_shapes_raise_one_error_naming_the_key(spec, match):
    with pytest.raises(ShapeError, match=match):
        shape_from_config(spec, "s")


def test_a_shape_from_the_config_equals_the_one_built_directly():
    assert shape_from_config({"box": {"size_mm": [10, 20, 30]}}) == Box((10.0, 20.0, 30.0))
    assert hash(Box((10, 20, 30))) == hash(Box((10.0, 20.0, 30.0)))
