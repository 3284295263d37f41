"""Published reference values: NIST SP 1065 NBS14 data sets (Stable32 results)."""

import csv

import imunoise
import numpy as np
import pytest

# statistic name in the reference tables -> (function, keyword arguments)
STATISTICS = {
    "adev": (imunoise.adev, {"overlapping": False}),
    "oadev": (imunoise.adev, {}),
    "mdev": (imunoise.mdev, {}),
    "tdev": (imunoise.tdev, {}),
    "hdev": (imunoise.hdev, {"overlapping": False}),
    "ohdev": (imunoise.hdev, {}),
    "totdev": (imunoise.totdev, {}),
}


def read_table(path):
    rows = [line for line in path.read_text().splitlines() if line and not line.startswith("#")]
    return list(csv.DictReader(rows))


def nbs14_10(data_dir):
    lines = [
        ln
        for ln in (data_dir / "nbs14_10point.txt").read_text().splitlines()
        if ln and not ln.startswith("#")
    ]
    return np.array(lines[1].split(), dtype=float)  # the frequency line


@pytest.mark.parametrize("name", sorted(STATISTICS))
def test_nbs14_10_point(data_dir, name):
    y = nbs14_10(data_dir)
    expected = {
        row["statistic"]: row for row in read_table(data_dir / "nbs14_10point_expected.csv")
    }
    func, kwargs = STATISTICS[name]
    r = func(y, 1.0, taus=np.array([1.0, 2.0]), **kwargs)
    np.testing.assert_array_equal(r.taus, [1.0, 2.0])
    want = [float(expected[name]["dev_tau1"]), float(expected[name]["dev_tau2"])]
    np.testing.assert_allclose(r.dev, want, rtol=1e-4)


@pytest.mark.parametrize("name", sorted(STATISTICS))
def test_nbs14_1000_point(data_dir, name):
    y = np.loadtxt(data_dir / "nbs14_1000_frequency.txt")
    assert len(y) == 1000
    expected = {
        row["statistic"]: row for row in read_table(data_dir / "nbs14_1000point_expected.csv")
    }
    row = expected[name]
    taus = [float(row[k]) for k in ("tau_a", "tau_b", "tau_c")]
    want = [float(row[k]) for k in ("dev_a", "dev_b", "dev_c")]
    func, kwargs = STATISTICS[name]
    r = func(y, 1.0, taus=np.array(taus), **kwargs)
    np.testing.assert_array_equal(r.taus, taus)
    np.testing.assert_allclose(r.dev, want, rtol=1e-4)
