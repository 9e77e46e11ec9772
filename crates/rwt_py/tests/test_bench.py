"""`python -m rwt_noise.bench` runs and prints its table and ratio line (small sizes)."""

import re

from rwt_noise import bench


def test_bench_prints_its_figures(capsys):
    bench.main(["--points", "3000", "--repeat", "1"])
    out = capsys.readouterr().out
    for row in ("scipy PoissonDisk (uniform)", "rwt.sample (uniform)",
                "rwt.sample (variable, 20:1 map)"):
        assert row in out
    ratio = re.search(r"rwt is (\d+)x scipy's points per second at (\d+) points; "
                      r"rho ([0-9.]+) against scipy's ([0-9.]+)", out)
    assert ratio, out
    assert 2700 < int(ratio.group(2)) < 3300
    assert float(ratio.group(3)) > 0.5 and float(ratio.group(4)) > 0.5
