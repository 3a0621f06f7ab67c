"""The readings of Eqs. 9-11 that the paper's lambda_max = 0.333 admits (grainlab.reproduction.readings)."""

from grainlab.reproduction.readings import lambda_max_table


def test_the_papers_lambda_max_admits_three_readings():
    rows = {r["reading"]: r for r in lambda_max_table(samples=60_000)}
    assert len(rows) == 12
    assert {k for k, r in rows.items() if r["admits"]} == {
        "angular/min/sum", "list/min/per_contact", "list/mean/per_contact"}
    # hand-worked: 0/60/120 gives 1/3 under the default, 1/6 per contact, 2/9 nearest with the mean anchor
    assert abs(rows["angular/min/sum"]["at_0_60_120"] - 1 / 3) < 1e-12
    assert abs(rows["angular/min/per_contact"]["at_0_60_120"] - 1 / 6) < 1e-12
    assert abs(rows["nearest/mean/sum"]["at_0_60_120"] - 2 / 9) < 1e-12
    # the closest arrangement is the largest under the default reading
    assert rows["angular/min/sum"]["largest"] == rows["angular/min/sum"]["at_0_60_120"]
