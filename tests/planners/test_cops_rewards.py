"""delve.planners.cops.rewards: frontier rewards with diminishing returns."""
import pytest

from delve.planners.cops import FrontierReward


def test_reward_tables_must_have_diminishing_returns():
    assert FrontierReward(table=(10, 15, 17)).marginals(3) == (10, 5, 2)
    with pytest.raises(ValueError, match="diminishing returns"):
        FrontierReward(table=(10, 15, 25)).marginals(3)
    r = FrontierReward()
    assert r.value(3) < 2 * r.value(2) - r.value(1)
