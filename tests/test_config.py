"""Configuration: the shipped configs validate; bad values give one message naming the key."""
import copy
from pathlib import Path

import pytest
import yaml

from synergrasp.config import ConfigError, set_id, synergy_sets, validate_config

ROOT = Path(__file__).resolve().parents[1]
SCHEMA = ROOT / "workflow" / "schemas" / "config.schema.yaml"
STUDY = yaml.safe_load((ROOT / "config" / "config.yaml").read_text())
SMALL = yaml.safe_load((ROOT / "tests" / "config" / "small.yaml").read_text())


@pytest.mark.parametrize("config", [STUDY, SMALL], ids=["study", "small"])
def test_shipped_configs_are_valid(config):
    validate_config(config, SCHEMA, n_synergies=15)


def test_study_config_holds_the_papers_parameters():
    assert STUDY["mechanics"]["mu"] == 1.5
    assert STUDY["mechanics"]["f_min_N"] == 0.1
    assert STUDY["mechanics"]["k_stru_N_per_mm"] == 1.0
    assert STUDY["mechanics"]["k_ss_Nmm_per_rad"] == 200.0
    sizes = {name: spec["size_mm"] for name, spec in STUDY["objects"].items()}
    assert sizes == {"obj1": [30, 30, 30], "obj2": [30, 60, 60], "obj3": [60, 60, 60], "obj4": [100, 60, 100]}
    alpha, beta = STUDY["grid"]["alpha_deg"], STUDY["grid"]["beta_deg"]
    n_alpha = (alpha["stop"] - alpha["start"]) / alpha["step"] + 1
    n_beta = (beta["stop"] - beta["start"]) / beta["step"] + 1
    assert n_alpha * n_beta == 1800


def _broken(path, value):
    config = copy.deepcopy(SMALL)
    node = config
    for key in path[:-1]:
        node = node[key]
    if value is _DELETE:
        del node[path[-1]]
    else:
        node[path[-1]] = value
    return config


_DELETE = object()


@pytest.mark.parametrize(
    ("path", "value", "expected"),
    [
        (("mechanics", "muu"), 1.5, "'mechanics': unknown key(s) ['muu']"),
        (("mechanics", "mu"), "high", "'mechanics.mu': 'high' is not of type 'number'"),
        (("mechanics", "mu"), -1.0, "'mechanics.mu'"),
        (("objects", "obj1", "size_mm"), [30, -1, 30], "'objects.obj1.size_mm[1]'"),
        (("objects", "obj1", "mass_kg"), 0, "'objects.obj1.mass_kg'"),
        (("solver", "method"), "newton", "'solver': unknown key(s) ['method']"),
        (("placement", "rotation_order"), "any", "allowed values: ['alpha_then_beta', 'beta_then_alpha']"),
        (("closure", "step_mm"), _DELETE, "'closure': 'step_mm' is a required property"),
        (("analyses", "fig4", "object"), "obj9", "unknown object 'obj9'; allowed values: ['obj1', 'obj4']"),
        (("closure", "sigma_closed"), 3.0, "'closure': unknown key(s) ['sigma_closed']"),
        (("mechanics", "gravity_direction"), [0, 0, 0], "'mechanics.gravity_direction'"),
        (("synergy_sets", "incremental_max"), 16, "exceeds the 15 synergies"),
    ],
)
def test_bad_values_name_the_key(path, value, expected):
    with pytest.raises(ConfigError) as info:
        validate_config(_broken(path, value), SCHEMA, n_synergies=15)
    assert expected in str(info.value)


def test_unknown_object_name_characters_are_rejected():
    config = copy.deepcopy(SMALL)
    config["objects"]["bad name"] = config["objects"].pop("obj1")
    with pytest.raises(ConfigError, match="'objects'.*'bad name'"):
        validate_config(config, SCHEMA)


def test_study_synergy_sets_are_the_75_distinct_sets():
    sets = synergy_sets(STUDY["synergy_sets"])
    # 15 incremental + (7 + 21 + 35) hierarchy - 3 shared ({S1}, {S1,S2}, {S1,S2,S3})
    assert len(sets) == 15 + 63 - 3
    assert sets["1-2-3"] == (1, 2, 3)
    assert "2-5-7" in sets and "1-2-3-4-5-6-7-8-9-10-11-12-13-14-15" in sets
    assert all(set_id(v) == k for k, v in sets.items())


def test_gfo_params_carry_the_mechanics_block():
    from synergrasp.config import gfo_params

    mech = dict(STUDY["mechanics"], gravity_direction=[0.0, 0.0, -2.0])
    params = gfo_params(mech, mass_kg=0.5)
    assert params.gravity_direction == (0.0, 0.0, -1.0)
    assert (params.mu, params.f_min, params.k_stru, params.k_ss) == (1.5, 0.1, 1.0, 200.0)
    # the wrench the contacts apply balances the weight: +z force of 0.5 kg x 9.81 m/s^2
    assert params.wrench()[2] == pytest.approx(0.5 * 9.81)
