import pytest

from workstation.errors import ParameterError
from workstation.params import Params
from workstation.params.ui import describe


def test_table_one_defaults():
    p = Params()
    assert p.steps.variance_window == 50 and p.steps.variance_threshold == 0.5
    assert p.acc.walking_s == 2.0 and (p.acc.still_min_s, p.acc.still_max_s) == (1.0, 8.0)
    assert p.gyro.window == 10 and p.gyro.threshold_rad_s == 1.1
    # ε_baro2 is 0.2, not the paper's 0.3: below the smallest storey (docs/decisions.md)
    assert p.baro.horizontal_hpa == 0.05 and p.baro.vertical_hpa == 0.2
    assert p.pdr.floor_hpa == 0.45 and p.pdr.heading_threshold_deg == 30
    assert p.pdr.confidence_threshold == 0.25 and p.pdr.initial_step_length_m == 0.63
    assert (p.belief.t_min_s, p.belief.t_max_s, p.belief.threshold) == (0.4, 1.0, 15.0)


def test_yaml_round_trip(tmp_path):
    p = Params().updated(
        **{"belief.threshold": 20, "pdr.start_node": "W0", "radiomap.backward_correction": False}
    )
    f = tmp_path / "p.yaml"
    p.save(f)
    assert Params.load(f) == p


@pytest.mark.parametrize(
    "text, message",
    [
        ("belief: {threshold: -1}\n", r"belief.threshold: -1.0 is outside \[0.0, 1000.0\]"),
        ("belief: {treshold: 3}\n", "belief: unknown parameter.*treshold"),
        ("colour: {a: 1}\n", "unknown section.*colour"),
        ("gyro: {window: 2.5}\n", "gyro.window: expected a whole number"),
        (
            "pdr: {heading_source: magic}\n",
            "pdr.heading_source: 'magic' is not one of gyro, compass",
        ),
        ("acc: {still_min_s: 9}\n", "still_min_s must not exceed"),
    ],
)
def test_bad_values_are_refused_with_the_key(tmp_path, text, message):
    f = tmp_path / "p.yaml"
    f.write_text(text)
    with pytest.raises(ParameterError, match=message):
        Params.load(f)


def test_describe_lists_every_parameter_with_a_range():
    d = describe()
    keys = {x["key"] for x in d}
    assert {"belief.threshold", "gyro.threshold_rad_s", "pdr.confidence_threshold"} <= keys
    assert all(x["help"] for x in d)
    for x in d:  # slider ranges sit inside the validation bounds and hold the default
        if x["ui_range"]:
            lo, hi = x["ui_range"]
            assert x["lo"] <= lo <= x["default"] <= hi <= x["hi"], x["key"]
