"""The one-command noise report: statistics, distributions, Allan deviation, noise model.

:func:`build` turns a short log (sample statistics, distributions) and a long log
(Allan deviation, noise model) into a directory::

    report.html    self-contained (figures embedded as data URIs), plain HTML + CSS
    report.md      the same content, figures linked from figures/
    figures/       every figure as PNG and SVG
    noise.json     fitted noise model (when the noise model is available)
    imu.yaml       Kalibr IMU noise file (when the noise model is available)
    ekf_bias_model.yaml  white noise, random walk and Gauss–Markov bias states per axis

With one log both analyses run on it. Sections follow a lab report: recording
summary (duration, rate, what the reader skipped), sample statistics, distribution
fits, Allan deviation per sensor, noise coefficients per axis in datasheet units
with uncertainties, datasheet comparison.

Modules: :mod:`.build` (:func:`build`, the context and the list of sections),
:mod:`.sections` (one function per section), :mod:`.document` (Markdown and HTML),
:mod:`.model_text` (a noise model as tables and sentences, also printed by
``imunoise fit``), :mod:`.formatting` (numbers, durations, gaps as text),
:mod:`.inputs` (reading the logs).
"""

from imunoise.report.build import SECTIONS, TAUS_PER_DECADE, Report, build
from imunoise.report.formatting import gap_note, terms_used
from imunoise.report.inputs import read_log
from imunoise.report.model_text import (
    comparison_rows,
    datasheet_rows,
    lab_rows,
    model_sentences,
)

__all__ = [
    "SECTIONS",
    "TAUS_PER_DECADE",
    "Report",
    "build",
    "comparison_rows",
    "datasheet_rows",
    "gap_note",
    "lab_rows",
    "model_sentences",
    "read_log",
    "terms_used",
]
