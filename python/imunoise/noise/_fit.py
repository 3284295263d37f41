"""Fitting the noise model to an Allan deviation: validation of the result, the
weighted least-squares fit (Rust) or the slope read-off, and the uncertainties
(Fisher information or parametric bootstrap)."""

from __future__ import annotations

import math
import numbers
import os
import warnings
from collections.abc import Sequence
from concurrent.futures import ThreadPoolExecutor
from dataclasses import dataclass, fields, replace

import numpy as np

from imunoise import display
from imunoise._core import fit as _core_fit
from imunoise._support import warn as _warn
from imunoise._support.deprecation import old_call_forms
from imunoise.errors import CoverageWarning, ImunoiseTypeError, ImunoiseValueError
from imunoise.noise import _ambiguity, _typed
from imunoise.noise._components import Components
from imunoise.noise._datasheet import datasheet_notes, datasheet_values, upper_bounds
from imunoise.noise._filter import OutputFilter, estimate_filter
from imunoise.noise._model import NoiseModel
from imunoise.noise._readoff import coverage, fit_slopes, measured, readoffs
from imunoise.noise._terms import (
    GM_MAX,
    MOTION_SLOT,
    PARAMS,
    RES_SLOT,
    SINE_SLOT,
    SKEW_SLOT,
    TERMS,
    TONES_MAX,
    term_variances,
)

#: Most simulated samples (replicates x record length) of ``fit(uncertainty=
#: "bootstrap")``: they are held at once, 8 bytes each (1.6 GB at the bound).
MAX_BOOTSTRAP_SAMPLES = 200_000_000


def _extract(result, tau_range):
    """Validate an Allan result; return taus (T,), var (T, C), edf (T, C), 1-D flag."""
    missing = [a for a in ("taus", "kind", "edf", "fs") if not hasattr(result, a)]
    if missing or not (hasattr(result, "var") or hasattr(result, "dev")):
        raise ImunoiseTypeError(
            f"result must be an AllanResult (from imunoise.adev); got {type(result).__name__} "
            f"without {missing or ['var']}"
        )
    if result.kind != "adev":
        raise ImunoiseValueError(
            f"result.kind must be 'adev' (the noise model is that of the Allan variance); "
            f"got {result.kind!r}"
        )
    taus = np.asarray(result.taus, dtype=float)
    var = np.asarray(result.var if hasattr(result, "var") else np.square(result.dev),
                     dtype=float)
    edf = np.asarray(result.edf, dtype=float)
    if taus.ndim != 1 or taus.size == 0:
        raise ImunoiseValueError(
            f"result.taus must be a non-empty 1-D array; got shape {taus.shape}")
    one = var.ndim == 1
    if one:
        var, edf = var[:, None], edf[:, None]
    if var.ndim != 2 or var.shape[0] != taus.size or edf.shape != var.shape:
        raise ImunoiseValueError(
            f"result.var and result.edf must have shape ({taus.size},) or ({taus.size}, k); "
            f"got {var.shape} and {edf.shape}"
        )
    if var.shape[1] == 0:
        raise ImunoiseValueError("result has no channels (var has 0 columns)")
    if not np.all(np.isfinite(taus)) or np.any(taus <= 0):
        raise ImunoiseValueError(f"result.taus must be finite and > 0; got {taus!r}")
    keep = np.ones(taus.size, dtype=bool)
    if tau_range is not None:
        try:
            lo, hi = (float(v) for v in tau_range)
        except (TypeError, ValueError):
            msg = f"tau_range must be (min, max) in seconds; got {tau_range!r}"
            raise ImunoiseValueError(msg) from None
        if not (lo <= hi):
            raise ImunoiseValueError(f"tau_range must satisfy min <= max; got {tau_range!r}")
        keep = (taus >= lo) & (taus <= hi)
        if not keep.any():
            raise ImunoiseValueError(
                f"tau_range {tau_range!r} contains none of result.taus "
                f"({taus.min():.3g} s .. {taus.max():.3g} s)"
            )
    cap = _edf_cap(result, taus)
    if cap is not None:
        edf = np.minimum(edf, cap[:, None])
    return taus[keep], var[keep], edf[keep], one


def _edf_cap(result, taus):
    """Largest EDF an IMU rate-noise type can give at each tau (white rate noise).

    For the noise types the model describes at mid and long τ (white, flicker
    and random-walk rate noise, α ≤ 0) the EDF of the Allan variance is largest
    for white rate noise (α = 0). Capping the result's EDF there keeps a noise
    type misidentified as phase noise (α = 2, whose EDF is ≈ N/2 at every τ) from
    dominating the weights. Overlapping: Riley, NIST SP 1065, Table 11 (white
    FM): edf = (3(N−1)/(2m) − 2(N−2)/N)·4m²/(4m² + 5), N phase points;
    non-overlapping: the number of terms.
    """
    n_terms = getattr(result, "n", None)
    if n_terms is None:
        return None
    n_terms = np.asarray(n_terms, dtype=float)
    if n_terms.shape != taus.shape:
        return None
    m = np.maximum(np.rint(taus * float(result.fs)), 1.0)
    if not getattr(result, "overlapping", True):
        return np.maximum(n_terms, 1.0)
    n_phase = n_terms + 2 * m  # overlapping ADEV has N - 2m terms over N phase points
    with np.errstate(divide="ignore", invalid="ignore"):
        cap = (3 * (n_phase - 1) / (2 * m) - 2 * (n_phase - 2) / n_phase) * 4 * m**2 / (
            4 * m**2 + 5)
    return np.where(np.isfinite(cap) & (cap > 1.0), cap, 1.0)


#: Largest Allan variance the fit takes: a term's coefficient is read as the variance
#: over its form's factor (2 ln2/π for B), which must not overflow float64 when squared
#: back.
_LARGEST_VARIANCE = 1e300


def _parse_terms(terms) -> tuple[dict[str, int], bool]:
    """``terms`` → ({kind: count}, select by score): ``"auto"`` allows every kind of term
    up to its most and selects; a sequence names exactly the terms fitted, each by the
    name ``fit(terms=...)`` asks for its kind by (the term classes' ``requested``)."""
    most = dict(_core_fit.TERM_MOST)
    if isinstance(terms, str) and terms == "auto":
        return most, True
    names = tuple(terms)
    kind_of = {cls.requested: cls.kind for cls in _typed.KINDS.values()}
    counts = dict.fromkeys(most, 0)
    for name in names:
        if name in kind_of:
            counts[kind_of[name]] += 1
    bad = [t for t in names if t not in kind_of]
    if bad or not names or any(n > most[kind] for kind, n in counts.items()):
        several = [f"{cls.requested!r} at most {most[kind]} times"
                   for kind, cls in _typed.KINDS.items() if most[kind] > 1]
        raise ImunoiseValueError(
            f"terms must be 'auto' or a non-empty sequence of {tuple(kind_of)} with "
            f"{', '.join(several)} and every other name at most once; got {terms!r}")
    return counts, False


@old_call_forms(keyword_only=("method", "terms", "tau_range"))
def fit(result, *, method: str = "wls", terms: str | Sequence[str] = "auto",
        tau_range: tuple[float, float] | None = None, uncertainty: str = "independent",
        replicates: int = 30, seed=None, warn_coverage: bool = True,
        spectrum=None, sensor: str = "gyro", output_filter: bool = True) -> NoiseModel:
    """Fit the noise model to an Allan deviation.

    Parameters
    ----------
    result : AllanResult or ImuLog
        From :func:`imunoise.adev` (overlapping or not); ``kind`` must be
        ``"adev"``. Taus with a non-finite or non-positive variance or EDF are
        ignored. A log (:func:`imunoise.read`) is analysed here: the Allan
        deviation of its ``sensor`` at 10 taus per decade and, unless
        ``spectrum`` is given, its Welch PSD (:func:`imunoise.psd`), from which
        the output filter is measured.
    method : {"wls", "slopes"}
        Log-space weighted least squares (default) or the IEEE 952 / MATLAB
        slope read-off (see the module docstring).
    terms : "auto" or sequence of {"Q", "N", "B", "K", "R", "GM", "sine", "resonance", \
"motion"}
        ``"auto"`` (default): the IEEE terms, up to three Gauss–Markov terms,
        up to two tones, a resonance and a bounded motion of the mount, the
        structure with the lowest BIC (the fewest terms that describe the
        curve). A sequence fits exactly those terms (``"GM"`` up to three times
        for Gauss–Markov terms, ``"sine"`` up to twice for tones, ``"resonance"`` once for
        a damped oscillator — with a skew, a second-order filter's quadrature part,
        where that lowers the BIC —, ``"motion"`` once for a bounded motion); a term the
        data push below zero is still 0.
    tau_range : (float, float), optional
        Only use taus in [min, max] seconds.
    uncertainty : {"independent", "bootstrap"}
        How the ``*_std`` are obtained. ``"independent"`` (default, instant):
        the inverse Fisher information of the fit, each octave of taus counted
        as one independent piece of evidence and the model discrepancy δ
        included. ``"bootstrap"``: parametric bootstrap — ``replicates`` records
        of the same length and rate are simulated from the fitted model
        (:func:`imunoise.simulate`; through the channel's output filter where
        one was measured), analysed with the same taus and refitted with the
        same structure (and filter); each ``*_std`` is the standard deviation
        over the replicates (≈ 0.6 s per replicate and channel for 5 h at 40 Hz).
    replicates : int
        ``"bootstrap"`` only: number of simulated records (≥ 5; default 30).
    seed : int, numpy.random.Generator or None
        ``"bootstrap"`` only: seed of the simulations, for reproducible results.
    warn_coverage : bool
        Warn when the model follows the curve poorly (below); False for callers
        that say it in their own words (the report, ``imunoise fit``).
    spectrum : Spectrum, optional
        The Welch PSD of the same sensor (:func:`imunoise.psd`, not smoothed; the
        same channels and rate): each fitted tone is checked against it
        (:mod:`imunoise.spectral_lines`) and reported as a line
        (:attr:`NoiseModel.lines`) only where the spectrum shows one. Such a tone
        is placed at the spectrum's frequency (a fraction of a bin against the
        Allan curve's few per cent) and the variances are fitted again around it:
        ``Tone.freq``, the line and the curve are one model. Without it the tones
        are reported unchecked: the Allan curve alone cannot tell a line from a
        filter's roll-off.
        The sensor's output filter is measured from it too (``output_filter``).
    sensor : {"gyro", "accel"}
        Which channel group of a log ``result`` is; ignored for an Allan result.
    output_filter : bool
        With a spectrum (or a log), take the sensor's output filter G(f) = ``|H(f)|²``
        from the spectrum's shape above its white region
        (:func:`imunoise.noise.estimate_filter`) and fit the white noise through it
        (:attr:`NoiseModel.filter`), so that no tone, resonance or Gauss–Markov
        term draws the filter's roll-off. False fits as without a spectrum (the
        tones are still checked against it). Without a spectrum there is no
        filter, and ``model.notes`` says so.

    Returns
    -------
    NoiseModel

    Warns
    -----
    RuntimeWarning
        When the model follows the measured curve at fewer than 80 % of the
        taus (:attr:`NoiseModel.coverage`): its coefficients then summarise a
        curve they do not describe; look at the residual panel of
        :func:`imunoise.plot.allan`.

    Notes
    -----
    The EDF of the result is capped at its white-rate-noise value (the largest
    for the α ≤ 0 noise types of an IMU) before weighting, see ``_edf_cap``.
    Standard uncertainties of the coefficients follow from those of their
    squares: u(N) = u(N²)/(2N); of a correlation time from that of ln τc.
    """
    return _fit(result, method=method, terms=terms, tau_range=tau_range,
                uncertainty=uncertainty, replicates=replicates, seed=seed,
                warn_coverage=warn_coverage, spectrum=spectrum, sensor=sensor,
                output_filter=output_filter)


def _fit(result, *, method, terms, tau_range, uncertainty, replicates, seed, warn_coverage,
         spectrum, sensor, output_filter, filters=None) -> NoiseModel:
    """:func:`fit`; ``filters``, when given, are the channels' output filters (None:
    none) in place of those the spectrum shows: a bootstrap refits its replicates,
    simulated through the point fit's filter, with that same filter."""
    if method not in ("wls", "slopes"):
        raise ImunoiseValueError(f"method must be 'wls' or 'slopes'; got {method!r}")
    if uncertainty not in ("independent", "bootstrap"):
        raise ImunoiseValueError(
            f"uncertainty must be 'independent' or 'bootstrap'; got {uncertainty!r}"
        )
    result, spectrum = _from_log(result, spectrum, sensor)
    if uncertainty == "bootstrap":
        if isinstance(replicates, bool) or not isinstance(replicates, numbers.Integral):
            raise ImunoiseTypeError(f"replicates must be an integer; got {replicates!r}")
        if replicates < 5:
            raise ImunoiseValueError(f"replicates must be >= 5; got {replicates}")
        n_record = _record_length(result)  # the length of every simulated replicate
        if replicates * n_record > MAX_BOOTSTRAP_SAMPLES:
            most = MAX_BOOTSTRAP_SAMPLES // n_record
            raise ImunoiseValueError(
                (f"replicates must be at most {most:,} for a record of {n_record:,} samples"
                 if most >= 5 else
                 f"a record of {n_record:,} samples is too long for a bootstrap (use "
                 f"uncertainty='independent')")
                + f" (the simulated records, replicates x samples, are held at once: at most "
                f"{MAX_BOOTSTRAP_SAMPLES:,}); got replicates={replicates:,}"
            )
    counts, select = _parse_terms(terms)
    mask = np.array([counts[_typed.IEEE[t].kind] > 0 for t in TERMS])
    _check_spectrum(spectrum, result)
    taus, var, edf, one = _extract(result, tau_range)
    dev_all, edf_raw = measured(result, taus)
    channels = var.shape[1]
    if filters is None:
        filters = _filters(spectrum, channels, output_filter and method == "wls")
    coef = np.zeros((channels, 5))
    std = np.full((channels, 5), np.nan)
    sup = np.zeros((channels, 5), dtype=bool)
    rng = np.full((channels, 5, 2), np.nan)
    gm = np.full((channels, GM_MAX, 2), np.nan)
    gm_std = np.full((channels, GM_MAX, 2), np.nan)
    sine = np.full((channels, TONES_MAX, 2), np.nan)  # amplitude, f0 per tone slot
    sine_std = np.full((channels, TONES_MAX, 2), np.nan)
    osc = np.full((channels, 4), np.nan)  # sigma, f_r, tau_r, skew
    osc_std = np.full((channels, 4), np.nan)
    moving = np.full((channels, 2), np.nan)  # sigma of the angle, tau_c
    moving_std = np.full((channels, 2), np.nan)
    stats = np.full((channels, 3), np.nan)  # discrepancy, chi2, n_eff
    cov = np.full((channels, PARAMS, PARAMS), np.nan)
    core: list = [None] * channels  # per channel: the core's terms and their covariance
    checked = [None] * channels  # per channel: its tones checked against the spectrum
    ambiguous: list = [[] for _ in range(channels)]  # per channel: the core's ties
    usable = []
    for c in range(channels):
        ok = np.isfinite(var[:, c]) & (var[:, c] > 0) & np.isfinite(edf[:, c]) & (edf[:, c] > 0)
        huge = ok & (var[:, c] > _LARGEST_VARIANCE)
        if huge.any():
            raise ImunoiseValueError(
                f"result's Allan variance for channel {c} is {var[huge, c].max():.3g} at tau = "
                f"{taus[huge][0]:.3g} s; the fit needs it ≤ {_LARGEST_VARIANCE:.0e} (a term's "
                "coefficient squared must stay within float64): rescale the data")
        if not ok.any():
            raise ImunoiseValueError(
                f"result has no usable tau for channel {c}: var and edf must be finite and > 0"
            )
        if ok.sum() < 2:
            raise ImunoiseValueError(
                f"result has {ok.sum()} usable tau for channel {c}; the fit needs at least 2 "
                "(var and edf finite and > 0)"
            )
        usable.append(ok)
    if method == "wls":
        # The Rust fit releases the GIL: channels run in parallel threads.
        def fit_channel(c):
            ok = usable[c]

            def core_fit(held=None):
                return _fit_wls(taus[ok], var[ok, c], edf[ok, c], float(result.fs), counts,
                                select, filters[c], held=held)

            if spectrum is None:
                return core_fit(), None
            return _at_spectral_lines(core_fit(), spectrum, c, core_fit)

        with ThreadPoolExecutor(max_workers=min(channels, os.cpu_count() or 1)) as pool:
            fits, checked = zip(*pool.map(fit_channel, range(channels)), strict=True)
        for c, out in enumerate(fits):
            coef[c], std[c], sup[c], gm[c], gm_std[c], sine[c], sine_std[c], osc[c], \
                osc_std[c], moving[c], moving_std[c] = out.arrays
            stats[c], cov[c], ambiguous[c] = out.stats, out.slot_cov, out.ties
            core[c] = out.core_terms, out.cov
            markov = [(a, b) for a, b in gm[c] if np.isfinite(a)]
            tones = [tuple(p) for p in sine[c] if np.isfinite(p[0])]
            oscs = [tuple(osc[c])] if np.isfinite(osc[c, 0]) else []
            motions = [tuple(moving[c])] if np.isfinite(moving[c, 0]) else []
            parts = term_variances(taus[usable[c]], result.fs, coef[c], markov, tones, oscs,
                                   motions)
            if filters[c] is not None:  # the white term through the filter
                parts[:, 1] *= filters[c].factor(taus[usable[c]])
            rng[c] = _support_range(parts, taus[usable[c]], sup[c])
    else:
        for c in range(channels):
            ok = usable[c]
            coef[c], std[c], sup[c], rng[c] = fit_slopes(taus[ok], var[ok, c], edf[ok, c], mask)
    def terms_of(c):
        """Channel ``c``'s typed terms: the core's fit, or the read-off's coefficients."""
        if core[c] is not None:
            return _typed.from_core(*core[c])
        return tuple(_typed.IEEE[name](float(coef[c, j]), float(std[c, j]))
                     for j, name in enumerate(TERMS) if coef[c, j] > 0)

    typed = [terms_of(c) for c in range(channels)]
    sheet_std = np.full((channels, 5), np.nan)  # bootstrap: of the datasheet values
    if uncertainty == "bootstrap":
        generator = np.random.default_rng(seed)
        for c in range(channels):
            if not typed[c]:
                continue
            options = dict(method=method, terms=[t.requested for t in typed[c]],
                           tau_range=tau_range)
            typed[c], sheet_std[c] = _bootstrap_std(
                result, n_record, typed[c], int(replicates), generator, options, filters[c])
            # the deprecated arrays' uncertainties from the terms'
            (_, std[c], _, _, gm_std[c], _, sine_std[c], _, osc_std[c], _,
             moving_std[c]) = _legacy_arrays(typed[c])
    std[~sup] = np.nan
    if method != "wls":  # the read-off's flags: a coefficient it did not place has no std
        typed = [terms_of(c) for c in range(channels)]
    typed = tuple(typed)
    requested = () if select or method != "wls" else tuple(terms)
    unplaced = [_unplaced(requested, typed[c]) for c in range(channels)]
    if any(unplaced):
        where = "; ".join(f"channel {c}: {', '.join(u)}" for c, u in enumerate(unplaced) if u)
        _warn.warn(f"fit(terms=...): the data put requested terms at 0 ({where}); the model "
                   "has the others (model.notes says which)", CoverageWarning)

    def shaped(a):
        out = np.array(a[0] if one else a)
        out.setflags(write=False)
        return out

    components = Components(
        **{k: shaped(coef[:, i]) for i, k in enumerate(TERMS)},
        **{k + "_std": shaped(std[:, i]) for i, k in enumerate(TERMS)},
        supported={k: shaped(sup[:, i]) for i, k in enumerate(TERMS)},
        tau_range={k: shaped(rng[:, i, :]) for i, k in enumerate(TERMS)},
        gm_sigma=shaped(gm[:, :, 0]),
        gm_tau=shaped(gm[:, :, 1]),
        gm_sigma_std=shaped(gm_std[:, :, 0]),
        gm_tau_std=shaped(gm_std[:, :, 1]),
        sine_amplitude=shaped(sine[:, :, 0]),
        sine_freq=shaped(sine[:, :, 1]),
        sine_amplitude_std=shaped(sine_std[:, :, 0]),
        sine_freq_std=shaped(sine_std[:, :, 1]),
        resonance_sigma=shaped(osc[:, 0]),
        resonance_freq=shaped(osc[:, 1]),
        resonance_tau=shaped(osc[:, 2]),
        resonance_skew=shaped(osc[:, 3]),
        resonance_sigma_std=shaped(osc_std[:, 0]),
        resonance_freq_std=shaped(osc_std[:, 1]),
        resonance_tau_std=shaped(osc_std[:, 2]),
        resonance_skew_std=shaped(osc_std[:, 3]),
        motion_sigma=shaped(moving[:, 0]),
        motion_tau=shaped(moving[:, 1]),
        motion_sigma_std=shaped(moving_std[:, 0]),
        motion_tau_std=shaped(moving_std[:, 1]),
        cov=shaped(cov),
        fs=float(result.fs),
    )
    record = _record_seconds(result, taus)
    sheet = datasheet_values(components, core, taus, method, record, filters)
    if uncertainty == "bootstrap":
        sheet = {k: (v, sheet_std[:, i]) for i, (k, (v, _)) in enumerate(sheet.items())}
    resolved = {k: (v > 0) & np.isfinite(v) for k, (v, _) in sheet.items()}
    fitted = [{k: v[c] for k, (v, _) in sheet.items()} for c in range(channels)]
    tied = tuple(_ambiguity.ties(ambiguous[c], fitted[c]) for c in range(channels))
    for c, channel_ties in enumerate(tied):
        for tie in channel_ties:
            resolved[tie.term][c] = False
    bounds = upper_bounds(taus, np.square(dev_all), edf_raw, filters)
    model = NoiseModel(
        **{k: shaped(np.where(resolved[k], v, np.nan)) for k, (v, _) in sheet.items()},
        **{k + "_std": shaped(np.where(resolved[k], e, np.nan)) for k, (_, e) in sheet.items()},
        supported={k: shaped(v) for k, v in resolved.items()},
        upper={k: shaped(np.where(resolved[k], np.nan, bounds[k])) for k in TERMS},
        notes=tuple((*datasheet_notes(typed[c], result.fs, record, method),
                     *(tie.note() for tie in tied[c]),
                     *_unplaced_note(unplaced[c]),
                     *_filter_notes(filters[c], spectrum, output_filter, method))
                    for c in range(channels)),
        lines=tuple(_lines(components, spectrum, c, checked[c]) for c in range(channels)),
        ties=tied,
        _arrays=components,
        terms=typed,
        method=method,
        kind=result.kind,
        fs=float(result.fs),
        overlapping=bool(getattr(result, "overlapping", True)),
        taus=_readonly(taus),
        coverage=shaped(np.zeros(channels)),
        discrepancy=shaped(stats[:, 0]),
        chi2=shaped(stats[:, 1]),
        n_eff=shaped(stats[:, 2]),
        readoff=readoffs(taus, dev_all, edf_raw, shaped),
        filter=filters,
    )
    cover = coverage(model, taus, dev_all, edf_raw)
    object.__setattr__(model, "coverage", shaped(cover))
    if method == "wls" and any(
            components.gauss_markov(c) or components.sine(c) or components.resonance(c)
            or components.motion(c) for c in range(channels)):
        _warn_sparse_grid(taus)
    for c in np.flatnonzero(cover < 0.8) if method == "wls" and warn_coverage else ():
        _warn.warn(
            f"the noise model follows the Allan deviation of channel {c} at only "
            f"{display.percent(cover[c])} of the taus (inside the 95 % interval or within "
            "5 %); its "
            "coefficients summarise a curve they do not describe: plot it with "
            "result.plot(model) or imunoise.plot.allan(result, model=model)",
            CoverageWarning,
        )
    return model


def _from_log(result, spectrum, sensor):
    """A log becomes its ``sensor``'s Allan deviation (10 taus per decade) and, unless
    given, its Welch PSD; an Allan result passes through."""
    from imunoise.readers.log import ImuLog

    if not isinstance(result, ImuLog):
        return result, spectrum
    from imunoise._support import schema as _schema
    from imunoise.allan import adev
    from imunoise.spectrum import psd

    if sensor not in ("gyro", "accel"):
        raise ImunoiseValueError(f"sensor must be 'gyro' or 'accel'; got {sensor!r}")
    y = getattr(result, sensor)
    if y is None:
        raise ImunoiseValueError(f"the log {result.source} has no {sensor} channel; pass "
                                 f"sensor={'accel' if sensor == 'gyro' else 'gyro'!r}")
    allan = adev(y, result.fs, taus=_schema.TAUS_PER_DECADE)
    return allan, spectrum if spectrum is not None else psd(y, result.fs)


def _filters(spectrum, channels: int, wanted: bool) -> tuple[OutputFilter | None, ...]:
    """Each channel's output filter measured from ``spectrum`` (None: none found, or
    not asked for)."""
    if spectrum is None or not wanted:
        return (None,) * channels
    return tuple(estimate_filter(spectrum, c) for c in range(channels))


def _filter_notes(found, spectrum, wanted: bool, method: str) -> tuple[str, ...]:
    """What a reader of one channel's values must know about its output filter."""
    if method != "wls" or not wanted:
        return ()
    if found is None and spectrum is None:
        return ("the output filter was not taken from a spectrum (fitted from the Allan "
                "deviation alone): a filter's roll-off at the short taus is drawn by the "
                "other terms; pass spectrum=imunoise.psd(x, fs) or fit the log",)
    if found is None:
        return ()
    return (f"the white noise passes the output filter measured from the spectrum: white "
            f"to {found.white_top:.3g} Hz, gain {found.gain[-1]:.2g} at "
            f"{found.fs / 2:g} Hz (model.filter)",)


def _check_spectrum(spectrum, result) -> None:
    """``spectrum`` must be a Welch PSD of the result's channels at its rate."""
    if spectrum is None:
        return
    from imunoise.spectral_lines import require_linear_grid
    from imunoise.spectrum import Spectrum

    if not isinstance(spectrum, Spectrum):
        raise ImunoiseTypeError(f"spectrum must be a Spectrum (imunoise.psd) or None; got "
                        f"{type(spectrum).__name__}")
    channels = 1 if np.ndim(result.dev) == 1 else np.shape(result.dev)[1]
    if spectrum.channels != channels:
        raise ImunoiseValueError(f"spectrum has {spectrum.channels} channels; the Allan result has "
                         f"{channels}")
    if not math.isclose(float(spectrum.fs), float(result.fs), rel_tol=1e-9):
        raise ImunoiseValueError(f"spectrum.fs must equal result.fs ({result.fs} Hz); got "
                         f"{spectrum.fs} Hz")
    require_linear_grid(spectrum)


def _at_spectral_lines(out: _ChannelFit, spectrum, channel: int,
                       refit) -> tuple[_ChannelFit, dict]:
    """One channel's fit ``out`` (:func:`_fit_wls`) with each tone the spectrum
    confirms moved to the spectrum's frequency and the variances fitted again by
    ``refit(held core terms)``, and each tone's check against ``spectrum`` by its
    final frequency. A line is a peak a fraction of a bin wide in the spectrum and a
    few per cent wide on the Allan curve: one model has the spectrum's frequency."""
    from imunoise import spectral_lines

    core_terms = out.core_terms
    checks = {}
    for t in _typed.from_core(core_terms, out.cov):
        if isinstance(t, _typed.Tone):
            checks[t.freq] = spectral_lines.check_line(spectrum, channel, t.freq, t.amplitude,
                                                       t.freq_std)
    moved: dict = {}
    for f, line in checks.items():
        if line.in_spectrum and line.frequency not in moved.values():
            moved[f] = line.frequency
    if all(moved.get(f, f) == f for f in checks):
        return out, checks
    held = []
    for kind, parameters in core_terms:
        if kind == "tone":
            f = parameters[1]
            if checks[f].in_spectrum and f not in moved:
                continue  # another tone has its line: the spectrum shows one there
            parameters = [parameters[0], moved.get(f, f)]
        held.append((kind, list(parameters)))
    again = refit(held)
    return replace(again, ties=out.ties), {moved.get(f, f): line for f, line in checks.items()}


def _lines(components, spectrum, channel: int, checked) -> tuple:
    """Each fitted tone of ``channel`` checked against ``spectrum`` (unchecked
    without one); ``checked``: the checks already made, by the tone's frequency."""
    from imunoise import spectral_lines

    tones = components.sine(channel)
    if spectrum is None:
        return tuple(spectral_lines.unchecked(a, f0) for a, f0 in tones)
    checked = checked or {}
    return tuple(replace(checked[f0], amplitude=a) if f0 in checked
                 else spectral_lines.check_line(spectrum, channel, f0, a) for a, f0 in tones)


#: Taus per decade below which a fitted line or correlated term is placed poorly.
SPARSE_TAUS_PER_DECADE = 5.0


def _warn_sparse_grid(taus) -> None:
    """Warn when the model has components beyond the IEEE terms and the grid is too
    sparse to place them: on octaves (3.3 taus per decade) the ADIS16405
    accelerometers' 0.53 Hz line went to a fast Gauss–Markov term or was left
    out, and N moved by up to 5 standard uncertainties from its value on 5 to 50
    taus per decade, which agree within 0.1."""
    taus = np.asarray(taus, dtype=float)
    if taus.size < 2:
        return
    density = (taus.size - 1) / math.log10(taus[-1] / taus[0])
    if density < SPARSE_TAUS_PER_DECADE:
        _warn.warn(
            f"the Allan deviation has {density:.1f} taus per decade and the model has "
            "lines or correlated terms, which a grid this sparse places poorly: its N, B "
            "and K can move by several standard uncertainties against a denser grid's; "
            "fit adev(..., taus=10) or denser",
            CoverageWarning,
        )


def _record_seconds(result, taus) -> float:
    """The record's duration behind an Allan result (s): its samples over its rate,
    or, where it does not say, its longest tau."""
    n_samples = getattr(result, "n_samples", None)
    longest = float(taus[-1])
    if not n_samples:
        return longest
    return max(float(n_samples) / float(result.fs), longest)


def _record_length(result) -> int:
    """Samples behind an Allan result: its ``n_samples`` when gap-free; with gaps,
    the gap-free length with as many terms at the shortest tau (the most of any
    channel), which is what a simulated replicate must match."""
    n_samples = getattr(result, "n_samples", None)
    if n_samples and not np.any(np.asarray(getattr(result, "missing", 0))):
        return int(n_samples)
    try:
        m0, n0 = int(np.asarray(result.m)[0]), int(np.max(np.asarray(result.n)[0]))
        overlapping = bool(result.overlapping)
    except (AttributeError, IndexError, TypeError):
        raise ImunoiseTypeError(
            "uncertainty='bootstrap' needs an AllanResult from imunoise.adev (with m, n and "
            "overlapping)"
        ) from None
    # Overlapping ADEV has N − 2m terms over N = n + 1 phase points; the
    # non-overlapping one ⌊n/m⌋ − 1 (exact at m = 1, the first tau of every grid).
    return n0 + 2 * m0 - 1 if overlapping else (n0 + 1) * m0


def _bootstrap_std(result, n, terms, replicates, rng, options, found=None):
    """``terms`` (one channel's) with the standard deviation of each parameter, and that
    of the datasheet values Q…R, over fits to records simulated from them with the
    rate and taus of ``result`` and its length ``n``. With the channel's output filter
    ``found`` the records pass through it and are refitted with it, as the point fit
    was."""
    from imunoise._simulation.like import simulate_terms
    from imunoise.allan import adev

    sims = simulate_terms(terms, n, result.fs, rng, channels=replicates, through=found)
    again = adev(sims, result.fs, taus=np.asarray(result.taus), overlapping=result.overlapping,
                 confidence=result.confidence)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", RuntimeWarning)
        refit = _fit(again, uncertainty="independent", replicates=replicates, seed=None,
                     warn_coverage=False, spectrum=None, sensor="gyro", output_filter=True,
                     filters=None if found is None else (found,) * replicates, **options)
    sheet = np.stack([refit.value(t) for t in TERMS], axis=1)  # NaN: not resolved
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", RuntimeWarning)  # all-NaN: no such term
        return _spread(terms, refit.terms), np.nanstd(sheet, axis=0, ddof=1)


def _spread(terms, replicas) -> tuple:
    """``terms`` (one channel's) with each parameter's uncertainty the standard deviation
    of that parameter over ``replicas`` (per replicate, its refitted terms): the k-th
    term of a kind against each replicate's k-th of that kind. A replicate without it
    has an IEEE coefficient at 0 (the data put it there) and another term missing."""
    out, seen = [], {}
    for term in terms:
        kind = type(term)
        k = seen[kind] = seen.get(kind, -1) + 1
        ieee = isinstance(term, _typed._Ieee)
        same = [[t for t in replica if type(t) is kind] for replica in replicas]
        spread = {}
        for f in fields(term):
            if f.name.endswith("_std"):
                continue
            v = np.array([float(getattr(s[k], f.name)) if len(s) > k else
                          (0.0 if ieee else np.nan) for s in same])
            spread[f.name + "_std"] = float(np.std(v, ddof=1) if ieee
                                            else np.nanstd(v, ddof=1))
        out.append(replace(term, **spread))
    return tuple(out)


def _readonly(a):
    out = np.array(a)
    out.setflags(write=False)
    return out


@dataclass(frozen=True)
class _ChannelFit:
    """One channel's core fit: its terms in the core's form (kind, parameters) with
    the covariance of their coordinates, the fit's statistics (discrepancy, χ²,
    n_eff), the ties the core found, and the deprecated ``Components`` arrays and
    slot covariance derived from them."""

    core_terms: list
    cov: np.ndarray
    stats: tuple[float, float, float]
    ties: list
    arrays: tuple
    slot_cov: np.ndarray


def _fit_wls(t, v, e, fs, counts, select, found=None, held=None) -> _ChannelFit:
    """One channel's core fit; ``held``: the core terms whose structure, times and
    frequencies are kept, their variances fitted again (no search)."""
    args = [np.ascontiguousarray(t), np.ascontiguousarray(v), np.ascontiguousarray(e), fs]
    args += [list(counts.items()), select] if held is None else [held]
    core = _core_fit.fit_noise if held is None else _core_fit.fit_noise_at
    try:
        if found is None:
            r = core(*args)
        else:
            r = core(*_less(args, found.excess(t)), filter=found.gain,
                     filter_level_std=float(found.white_std))
    except ValueError as exc:
        raise ImunoiseValueError(f"cannot fit the noise model to result: {exc}") from None
    cov = np.asarray(r.cov)
    return _ChannelFit(core_terms=r.terms, cov=cov, stats=(r.discrepancy, r.chi2, r.n_eff),
                       ties=r.ambiguous, arrays=_legacy_arrays(_typed.from_core(r.terms, cov)),
                       slot_cov=_slot_covariance(r.terms, cov))


def _legacy_arrays(terms):
    """The deprecated ``Components`` arrays of one channel from its typed terms:
    IEEE coefficients, their stds and support, then (value, std) per Gauss–Markov
    slot, tone slot, the resonance and the motion (NaN in unused slots)."""
    coef, std = np.zeros(5), np.full(5, np.nan)
    markov, markov_std = np.full((GM_MAX, 2), np.nan), np.full((GM_MAX, 2), np.nan)
    sine, sine_std = np.full((TONES_MAX, 2), np.nan), np.full((TONES_MAX, 2), np.nan)
    osc, osc_std = np.full(4, np.nan), np.full(4, np.nan)
    moving, moving_std = np.full(2, np.nan), np.full(2, np.nan)
    k_gm = k_tone = 0
    for term in terms:
        if isinstance(term, _typed._Ieee):
            j = TERMS.index(term.name)
            coef[j], std[j] = term.value, getattr(term, term.name + "_std")
        elif isinstance(term, _typed.GaussMarkov):
            markov[k_gm] = term.sigma, term.tau_c
            markov_std[k_gm] = term.sigma_std, term.tau_c_std
            k_gm += 1
        elif isinstance(term, _typed.Tone):
            sine[k_tone] = term.amplitude, term.freq
            sine_std[k_tone] = term.amplitude_std, term.freq_std
            k_tone += 1
        elif isinstance(term, _typed.Resonance):
            osc[:] = term.sigma, term.freq, term.tau, term.skew
            osc_std[:] = term.sigma_std, term.freq_std, term.tau_std, term.skew_std
        elif isinstance(term, _typed.Motion):
            moving[:] = term.sigma, term.tau_c
            moving_std[:] = term.sigma_std, term.tau_c_std
    supported = coef > 0
    return (coef, std, supported, markov, markov_std, sine, sine_std, osc, osc_std, moving,
            moving_std)


def _unplaced(requested, terms) -> list[str]:
    """The requested terms (``fit(terms=...)`` names) that one channel's fit has not:
    the data put their variance at 0."""
    left = list(requested)
    for term in terms:
        if term.requested in left:
            left.remove(term.requested)
    return left


def _unplaced_note(names) -> tuple[str, ...]:
    if not names:
        return ()
    return (f"requested {', '.join(names)} came out at 0: the data hold none of "
            f"{'it' if len(names) == 1 else 'them'} at this record's length and noise",)


def _slot_covariance(core_terms, cov):
    """The core's covariance, term after term, laid out in the deprecated
    ``Components.cov`` slots (0 for slots no term fills)."""
    out = np.zeros((PARAMS, PARAMS))
    slots = []
    counts = {"gauss_markov": 0, "tone": 0}
    for kind, _ in core_terms:
        if kind in _typed.KINDS and issubclass(_typed.KINDS[kind], _typed._Ieee):
            slots.append(TERMS.index(_typed.KINDS[kind].name))
        elif kind == "gauss_markov":
            slots += [5 + 2 * counts[kind], 6 + 2 * counts[kind]]
            counts[kind] += 1
        elif kind == "tone":
            slots += [SINE_SLOT + 2 * counts[kind], SINE_SLOT + 2 * counts[kind] + 1]
            counts[kind] += 1
        elif kind == "resonance":
            slots += [RES_SLOT, RES_SLOT + 1, RES_SLOT + 2, SKEW_SLOT]
        elif kind == "motion":
            slots += [MOTION_SLOT, MOTION_SLOT + 1]
        else:  # a kind newer than the deprecated view: not in it
            slots += [-1] * _typed.COORDINATES[kind]
    index = np.array(slots, dtype=int)
    kept = index >= 0
    out[np.ix_(index[kept], index[kept])] = cov[np.ix_(kept, kept)]
    return out


def _less(args, excess):
    """The fit's arguments with ``excess`` taken from the measured Allan variance, its
    EDF scaled to the same absolute sampling error (a tau left with nothing dropped).

    The filter's share of the flicker and walk (:meth:`OutputFilter.excess`, from the
    spectrum's own levels) is taken off this way: the core passes only the white term
    through the filter, and where the filter leaves little of it (an 11-tap Bartlett
    FIR keeps 0.4 % of the white variance at one sample) the flicker's unfiltered
    (2 ln2/π)B² would be 9 % of the curve there."""
    t, v, e = args[:3]
    less = v - excess
    keep = less > 0
    return [np.ascontiguousarray(t[keep]), np.ascontiguousarray(less[keep]),
            np.ascontiguousarray((e * (less / v) ** 2)[keep]), *args[3:]]


def _support_range(parts, t, sup, min_share=0.25):
    """Per IEEE term, the fitted taus where it is at least ``min_share`` of the
    whole model (Gauss–Markov terms included)."""
    total = parts.sum(axis=1)
    basis = parts[:, :5]
    out = np.full((5, 2), np.nan)
    with np.errstate(divide="ignore", invalid="ignore"):
        share = basis / total[:, None]
    for i in range(5):
        if sup[i]:
            hit = t[share[:, i] >= min_share]
            if hit.size:
                out[i] = hit.min(), hit.max()
    return out


