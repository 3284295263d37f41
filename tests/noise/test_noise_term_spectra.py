"""Each typed term's spectrum and its Allan variance are one model: the term's
one-sided PSD (``Term.psd``) integrated against the discrete Allan kernel gives the
core's Allan variance; a model's PSD panel (``spectrum.model_psd_terms``) and its
simulation (``simulate(like=model)``) are built from the same terms."""

import warnings

import imunoise
import numpy as np
import pytest
from imunoise.noise import _typed
from imunoise.spectrum import model_psd_terms
from scipy.signal import butter, lfilter, welch

FS = 100.0
GRID = np.linspace(0.0, FS / 2, 2_000_001)[1:]

#: Kinds whose PSD and Allan variance are both the sampled process's, exactly.
EXACT = [_typed.White(1e-3), _typed.Quantization(1e-5), _typed.GaussMarkov(1e-3, 0.05),
         _typed.Resonance(1e-3, 7.0, 0.3, 0.5), _typed.Resonance(1e-3, 2.0, 5.0, -0.3),
         _typed.Motion(1e-3, 2.0), _typed.Motion(1e-3, 0.03)]
#: Kinds whose Allan variance is the continuous form (2 ln2/π·B², K²τ/3): equal to the
#: sampled PSD's only once the cluster is many samples long.
CONTINUOUS = [_typed.Flicker(1e-4), _typed.RandomWalk(1e-5)]


def allan_of_psd(term, m):
    """σ²(τ = m/fs) = ∫₀^{fs/2} S(f)·2 sin⁴(πfm/fs)/(m² sin²(πf/fs)) df."""
    kernel = 2 * np.sin(np.pi * GRID * m / FS) ** 4 / (m * m * np.sin(np.pi * GRID / FS) ** 2)
    return np.trapezoid(term.psd(GRID, FS) * kernel, GRID)


@pytest.mark.parametrize("term", EXACT, ids=lambda t: t.label())
def test_a_sampled_terms_psd_integrates_to_its_allan_variance(term):
    for m in (1, 2, 5, 20, 100):
        want = term.allan_variance([m / FS], FS)[0]
        assert allan_of_psd(term, m) == pytest.approx(want, rel=1e-9), m


@pytest.mark.parametrize("term", CONTINUOUS, ids=lambda t: t.label())
def test_a_power_laws_psd_integrates_to_its_allan_variance_over_long_clusters(term):
    for m in (20, 100):
        want = term.allan_variance([m / FS], FS)[0]
        assert allan_of_psd(term, m) == pytest.approx(want, rel=5e-3), m
    # a short cluster sees the sampled spectrum: the continuous form is off there
    assert abs(allan_of_psd(term, 1) / term.allan_variance([1 / FS], FS)[0] - 1) > 0.1


def test_a_tone_has_no_density():
    assert _typed.Tone(1e-3, 5.0).psd(GRID[:10], FS) is None


def test_the_motions_psd_is_the_welch_estimate_of_its_process():
    x = imunoise.simulate(2_000_000, FS, motion=(1e-3, 0.5), seed=1)
    f, p = welch(x, FS, nperseg=4096)
    keep = (f > 0.05) & (f < 45)
    ratio = p[keep] / _typed.Motion(1e-3, 0.5).psd(f[keep], FS)
    # 977 averages: each bin within ±15 % at 1e-6 chance of a miss per bin
    assert np.all(np.abs(ratio - 1) < 0.15), (ratio.min(), ratio.max())


def test_a_models_psd_panel_holds_every_term_with_a_density():
    x = imunoise.simulate(720_000, FS, N=1e-4, motion=(3e-4, 5.0), gm=[(2e-4, 0.04)],
                          seed=2)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        model = imunoise.fit(imunoise.adev(x, FS, taus=20), terms=["N", "GM", "motion"])
    parts = model_psd_terms(model, GRID[::1000])
    assert set(parts) == {"N", "GM1", "motion"}
    for term, name in zip(model.terms[0], ("N", "GM1", "motion"), strict=True):
        assert np.array_equal(parts[name], term.psd(GRID[::1000], FS))


def test_simulate_like_a_model_passes_its_output_filter():
    # a 4th-order low-pass at fs/10: the model's curve is the filter's at short
    # taus, and a record simulated like the model follows it there
    x = imunoise.simulate(360_000, FS, N=1e-3, B=1e-5, seed=3)
    b, a = butter(4, 10 / (FS / 2))
    x = lfilter(b, a, x)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        model = imunoise.fit(imunoise.adev(x, FS, taus=10), spectrum=imunoise.psd(x, FS))
    assert model.filter[0] is not None
    again = imunoise.simulate(360_000, FS, like=model, seed=4)
    taus = np.array([0.01, 0.02, 0.05, 0.1])
    seen = imunoise.adev(again, FS, taus=taus).dev
    assert seen == pytest.approx(model.predict(taus).dev, rel=0.03)
    unfiltered = imunoise.simulate(360_000, FS, N=float(model.N), seed=4)
    assert imunoise.adev(unfiltered, FS, taus=taus).dev[0] > 2 * seen[0]
