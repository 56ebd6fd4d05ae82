"""aeromag.batch: a process pool, results in input order, errors kept."""

import pytest

import aeromag


def square_or_fail(x):
    if x == 3:
        raise aeromag.BadInputError("three is bad input", file=f"flight_{x}.csv")
    return x * x


def test_results_in_order_and_errors():
    assert aeromag.batch(square_or_fail, [5, 1, 4], processes=2) == [25, 1, 16]
    out = aeromag.batch(square_or_fail, [1, 3, 2], processes=2, errors="return")
    assert out[0] == 1 and out[2] == 4
    assert isinstance(out[1], aeromag.BadInputError) and out[1].file == "flight_3.csv"
    with pytest.raises(aeromag.BadInputError, match="three"):
        aeromag.batch(square_or_fail, [1, 3], processes=2)
    # processes=-3 ran with one process without a word.
    for bad in (-3, 0, 1.5, True):
        with pytest.raises(ValueError, match="processes"):
            aeromag.batch(square_or_fail, [1], processes=bad)
    seen = []
    aeromag.batch(square_or_fail, [1, 2], processes=1, progress=lambda s, d, t: seen.append((d, t)))
    assert seen[-1] == (2, 2)
