"""Sensor settings: what they accept, what they refuse (naming the key), and when they are ideal."""

from __future__ import annotations

import pytest

from freefloat.dynamics.sensors import Channel, MomentumKalman, SensorSettings
from freefloat.errors import InvalidArgument


@pytest.mark.parametrize(("keys", "named"), [({"noise": -0.1}, "noise"), ({"noise": [[0.1]]}, "noise"),
                                             ({"bias": "a"}, "bias"), ({"delay": -1}, "delay"),
                                             ({"delay": 1.5}, "delay"), ({"every": 0}, "every")])
def test_a_bad_channel_is_refused_naming_its_key(keys, named):
    """Negative noise, a matrix, text, a negative or fractional delay, a zero sampling period:
    refused, the message naming the key."""
    with pytest.raises(InvalidArgument, match=named):
        Channel(**keys)


@pytest.mark.parametrize(("keys", "named"), [({"linear_process_noise": 0.0}, "linear_process_noise"),
                                             ({"false_alarm": 1.0}, "false_alarm"),
                                             ({"restart": [[0.1]]}, "restart")])
def test_bad_estimator_settings_are_refused_naming_their_key(keys, named):
    """A zero random walk, a false-alarm probability of 1, restart times that are not a list:
    refused, the message naming the key."""
    with pytest.raises(InvalidArgument, match=named):
        MomentumKalman(**keys)


def test_a_group_that_is_not_a_channel_is_refused():
    """A number where a Channel belongs is refused, naming the group."""
    with pytest.raises(InvalidArgument, match="joint_rate"):
        SensorSettings(joint_rate=0.01)  # type: ignore[arg-type]


@pytest.mark.parametrize("changed", [{"joint_rate": Channel(noise=0.01)}, {"base_pose": Channel(bias=(0, 0, 1e-3))},
                                     {"base_twist": Channel(delay=1)}, {"joint_position": Channel(every=2)},
                                     {"momentum": MomentumKalman()}])
def test_any_imperfection_makes_the_sensors_non_ideal(changed):
    """The defaults are ideal; noise, bias, delay, slower sampling or an estimator is not."""
    assert SensorSettings().ideal
    assert not SensorSettings(**changed).ideal
