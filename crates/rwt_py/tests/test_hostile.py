"""The second hostile pass against the Python package: Ctrl-C during long calls (the first
one included), limits raised to their maximum, arrays whose conversion alone took
gigabytes, and point sets whose analysis was NaN. Each case failed before its fix."""

import signal
import subprocess
import sys
import textwrap
import time

import numpy as np
import pytest

import rwt_noise as rwt

# Runs in a child process: sends itself SIGINT `delay` s into a long call, made as the
# process's first call to rwt, and reports how late the KeyboardInterrupt came.
_INTERRUPTED = textwrap.dedent("""
    import os, signal, sys, threading, time
    # Python leaves SIGINT ignored when it starts with it ignored (under `cmd &` in a
    # script): Ctrl-C's handler is what is tested, so it is installed whatever the parent did.
    signal.signal(signal.SIGINT, signal.default_int_handler)
    import numpy as np
    import rwt_noise as rwt
    call = sys.argv[1]
    delay = float(sys.argv[2])
    threading.Timer(delay, lambda: os.kill(os.getpid(), signal.SIGINT)).start()
    started = time.monotonic()
    try:
        if call == "sample":
            rwt.sample((0, 0, 3000, 3000), 0.5, budget=10**9, tile_size=1)
        elif call == "map":
            rwt.sample((0, 0, 3000, 3000), np.full((64, 64), 0.5), budget=10**9, tile_size=1)
        elif call == "stipple":
            rwt.stipple(np.zeros((2048, 2048)), render=True)
        print("finished", time.monotonic() - started)
    except KeyboardInterrupt:
        print("interrupted", time.monotonic() - started - delay)
""")


@pytest.mark.parametrize("call", ["sample", "map", "stipple"])
def test_ctrl_c_interrupts_a_long_first_call_at_once(call):
    # Ignored until the call ended (37 s late once), its result then thrown away; during a
    # process's first call it became "PanicException: Failed to access NumPy array API
    # capsule".
    for delay in (0.05, 0.5):
        run = subprocess.run([sys.executable, "-c", _INTERRUPTED, call, str(delay)],
                             capture_output=True, text=True, timeout=120)
        assert run.returncode == 0, run.stderr
        assert "Panic" not in run.stderr, run.stderr
        words = run.stdout.split()
        assert words and words[0] == "interrupted", (call, delay, run.stdout, run.stderr)
        assert float(words[1]) < 0.5, (call, delay, run.stdout)


def test_raised_limits_are_typed_errors_not_an_abort():
    # The interpreter was killed by an allocation of 82 PB.
    grey = np.full((48, 64), 0.4)
    with pytest.raises(ValueError, match="raster pixels across"):
        rwt.stipple(grey, radius=1e-6, max_dots=2**64 - 1)
    with pytest.raises(ValueError, match="points 0 must be positive"):
        rwt.stipple(grey, dots=0)
    with pytest.raises(ValueError, match="raster pixels across at scale"):
        rwt.stipple(grey, scale=1e-300)


def test_huge_arrays_are_refused_on_their_shape_before_a_copy():
    # An 8-byte broadcast view of 20000 x 20000: converting it took 8.9 GB.
    view = np.broadcast_to(np.float64(1.0), (20000, 20000))
    with pytest.raises(ValueError, match="more than 16777216 values"):
        rwt.sample((0, 0, 1, 1), view)
    with pytest.raises(rwt.BudgetError, match="max_image_pixels"):
        rwt.stipple(np.broadcast_to(np.uint8(0), (20000, 20000)))


@pytest.mark.parametrize("low, side", [(0.0, 1e-308), (-1e300, 2e300), (1e15, 1.0)])
def test_points_on_a_degenerate_extent_raise_instead_of_nan(low, side):
    # NaN, inf and -1756 dB.
    points = low + np.random.default_rng(1).random((100, 2)) * side
    with pytest.raises(ValueError, match="no area an analysis can measure"):
        rwt.analyse(points, (low, low, low + side, low + side))
