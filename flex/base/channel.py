"""The headline channel's filter: how a run's series are low-passed before a headline is read
on them (:func:`flex.dynamics.advice.channel_datasets`), and how a link's stress field and a
joint's force vector are (:mod:`flex.dynamics.link_outputs`, :mod:`flex.bodies.exact_beam`,
:mod:`flex.dynamics.collect`).

The cut-off itself is the scene's (:func:`flex.dynamics.advice.channel_cutoff_Hz`); this
module holds what does not depend on the scene: the filter's order, padding and
undetermined tail, and :func:`channel_filter`, the one filter for a run's sampling.

A field's peak is read as the largest of its low-passed points, never as the low-passed
largest point: the largest stress over a link at each instant is an envelope of a field
ringing at ~5 % of it, and a low-pass of an envelope rectifies that ringing (on the 1 mm
plate's exact beam its channel peak moved by +-1 % without order under element and step
refinement, 27.59 / 27.13 / 27.30 MPa at 64 / 128 / 256 elements). Low-passing each
element's section forces first, then taking the largest stress, converges at order 2 in the
elements: 26.773, 26.825, 26.838, 26.840 MPa at 32 to 256 elements, within 2e-6 of itself
from h = 1e-5 to 2.5e-6 s (session 13, ``/tmp/s13/stressexp.py``). A joint force's modulus
is such a nonlinear reading too: it is the modulus of the low-passed force vector
(:mod:`flex.dynamics.collect`).
"""

from __future__ import annotations

from collections.abc import Callable

import numpy as np

from flex.base.lowpass import zero_phase_lowpass

#: order of the channel's Butterworth low-pass (run forward and backward: zero phase, twice
#: the attenuation)
CHANNEL_ORDER = 4
#: a cut-off above this fraction of the sampling's Nyquist frequency leaves the series as they
#: are: the samples hold no content above it worth filtering
CHANNEL_NYQUIST_FRACTION = 0.8
#: the channel filter's padding at each end, in periods of its cut-off
CHANNEL_PAD_PERIODS = 3.0
#: the channel's last samples within this many cut-off periods of the run's end are not
#: determined by the run: the zero-phase filter reads its padding there, a guess of how the
#: series goes on (the odd extension pins the channel to the raw last sample, ripple and all:
#: a 1 mm plate's joint force read 41 N at the end of a 10 ms run at h = 5e-6 s against a
#: deployment peak of 26.9 N at h = 1e-5 and 2.5e-6 s). A unit step in the padding moves the
#: channel by 2 % one period before the end, 0.5 % at 1.5 and 0.12 % at 2 (4th order, both
#: ways). ``channel/determined`` marks them; the headline readers stop before them
CHANNEL_EDGE_PERIODS = 2.0
#: what a channel series means, as a version: 2 reads a link's stress peaks on its low-passed
#: field (module doc), 1 low-passed the peak series itself; 3 also reads a joint force's
#: modulus on the low-passed force vector (a modulus rectifies ringing across the force as a
#: peak over a field does); 4 reads the whole-run peaks and the histories on the channel too
#: (the slider position joins its series): raw, the step's unresolved top mode put them
#: outside the asymptotic range; 5 reads a peak at its crest between samples (the parabola's
#: vertex, :func:`flex.data.headlines.crest_value`). Part of a sweep case's identity
#: (:func:`flex.sweep.case_files.case_hash`): a case file of another version is rerun
CHANNEL_FORMAT_VERSION = 5

#: a filter of a run's series: samples along axis 0 in, the same shape out, low-passed
ChannelFilter = Callable[[np.ndarray], np.ndarray]


def undetermined_samples(time_s: np.ndarray, cutoff_Hz: float) -> int:
    """How many of the run's last samples the channel does not determine
    (:data:`CHANNEL_EDGE_PERIODS` cut-off periods at the run's median sampling)."""
    sample_s = float(np.median(np.diff(time_s)))
    return int(np.ceil(CHANNEL_EDGE_PERIODS / (cutoff_Hz * sample_s)))


def channel_filter(time_s: np.ndarray, cutoff_Hz: float | None) -> ChannelFilter | None:
    """The headline channel's filter for a run sampled at ``time_s`` [s]: a zero-phase
    :data:`CHANNEL_ORDER`-th order Butterworth low-pass at ``cutoff_Hz`` [Hz] with
    :data:`CHANNEL_PAD_PERIODS` of odd padding; None without a cut-off (nothing flexible),
    with fewer than 16 samples, when the sampling holds nothing above the cut-off
    (:data:`CHANNEL_NYQUIST_FRACTION`) or when the run is shorter than twice its
    undetermined tail (:func:`undetermined_samples`): the run then has no channel."""
    time_s = np.asarray(time_s, dtype=float)
    if cutoff_Hz is None or time_s.size < 16:
        return None
    sample_s = float(np.median(np.diff(time_s)))
    if not cutoff_Hz < CHANNEL_NYQUIST_FRACTION * 0.5 / sample_s:
        return None
    if time_s.size < 2 * undetermined_samples(time_s, cutoff_Hz):
        return None
    # padding (odd extension) of CHANNEL_PAD_PERIODS cut-off periods: the filter's transient
    # has died out before the series starts (scipy's default, 27 samples, left a 1 % error on
    # a crest 0.8 ms after the start at a 1 kHz cut-off; tests/test_headline_channel.py)
    pad = min(time_s.size - 1, int(np.ceil(CHANNEL_PAD_PERIODS / (cutoff_Hz * sample_s))))

    def low_pass(series: np.ndarray) -> np.ndarray:
        return zero_phase_lowpass(series, CHANNEL_ORDER, cutoff_Hz, 1.0 / sample_s, pad)
    return low_pass


def channel_text(cutoff_Hz: float) -> str:
    """How a channel series' description says what it is."""
    return (f"on the headline channel (zero-phase {CHANNEL_ORDER}th-order Butterworth low-pass "
            f"at {cutoff_Hz:.4g} Hz)")


__all__ = ["CHANNEL_EDGE_PERIODS", "CHANNEL_FORMAT_VERSION", "CHANNEL_NYQUIST_FRACTION",
           "CHANNEL_ORDER", "CHANNEL_PAD_PERIODS", "ChannelFilter", "channel_filter",
           "channel_text", "undetermined_samples"]
