"""`python -m rwt_noise.bench` runs and prints its table and ratio line (small sizes)."""

import re

from rwt_noise import bench


def test_bench_prints_its_figures(capsys):
    bench.main(["--points", "3000", "--repeat", "1", "--scaling", "2000,20000"])
    out = capsys.readouterr().out
    for row in ("scipy PoissonDisk (uniform)", "rwt.sample (uniform)",
                "rwt.sample (variable, 20:1 map)"):
        assert row in out
    ratio = re.search(r"rwt is (\d+)x scipy's points per second at (\d+) points; "
                      r"rho ([0-9.]+) against scipy's ([0-9.]+)", out)
    assert ratio, out
    assert 2700 < int(ratio.group(2)) < 3300
    assert float(ratio.group(3)) > 0.5 and float(ratio.group(4)) > 0.5
    assert "rwt.sample (radius=" in out and "rwt.sample (uniform, mask=disc)" in out
    scaling = re.findall(r"rwt.sample / Rust query\s+(\d+)\s+([0-9.]+)\s+([0-9.]+)\s+([0-9.]+)", out)
    assert [abs(int(c) / n - 1) < 0.05 for (c, *_), n in zip(scaling, (2000, 20000))] == [True] * 2
