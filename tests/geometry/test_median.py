"""geometry.median.median: np.median's number, bit for bit, without importing numpy.ma."""

import subprocess
import sys

import numpy as np

from softdesign.geometry.median import median


def test_median_is_numpys_median_bit_for_bit():
    rng = np.random.default_rng(7)
    for n in range(1, 60):
        values = rng.normal(3.0, 1.0, n) * 10.0 ** rng.uniform(-3, 3)
        assert median(values) == float(np.median(values)), n
    assert median([2.0, 1.0]) == 1.5
    assert median([5.0]) == 5.0
    assert median(np.arange(12.0).reshape(3, 4)) == 5.5  # np.median's whole-array median


def test_a_nan_gives_nan_as_numpy_does():
    assert np.isnan(median([1.0, np.nan, 3.0]))


def test_median_does_not_import_numpy_ma():
    code = ("import sys, numpy as np; from softdesign.geometry.median import median; "
            "median(np.arange(5.0)); print('numpy.ma' in sys.modules)")
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True).stdout
    assert out.strip() == "False"
