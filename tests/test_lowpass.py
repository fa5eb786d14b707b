"""The zero-phase Butterworth low-pass of the headline channel against an independent
implementation, scipy.signal's (butter + sosfiltfilt), which flex does not import at run
time (flex.base.lowpass: 0.6 s of import)."""

import numpy as np
import pytest

from flex.base.lowpass import zero_phase_lowpass

CASES = [  # sampling [Hz], cut-off [Hz], samples, pad: the channel's range and its edges
    (11_500.0, 1_000.0, 345, 40),  # a 1 mm plate's run at its 1 % step
    (1e6, 200.0, 30_000, 15_000),  # a fine step, a low cut-off: poles close to z = 1
    (1e4, 4_900.0, 200, 50),  # a cut-off close to Nyquist
    (1e4, 4_000.0, 100, 0),  # no padding
    (1e5, 50.0, 3_000, 2_999),  # the longest padding allowed
]


@pytest.mark.parametrize("order", [1, 2, 3, 4, 6])
@pytest.mark.parametrize(("sample_Hz", "cutoff_Hz", "samples", "pad"), CASES)
def test_it_computes_what_scipy_signal_computes(order, sample_Hz, cutoff_Hz, samples, pad):
    from scipy.signal import butter, sosfiltfilt

    rng = np.random.default_rng(order)
    time_s = np.arange(samples) / sample_Hz
    series = np.column_stack([np.sin(2 * np.pi * 0.3 * cutoff_Hz * time_s)
                              + 0.1 * rng.standard_normal(samples),
                              np.cumsum(rng.standard_normal(samples)),
                              2.0 + 1e-4 * np.cos(2 * np.pi * 3 * cutoff_Hz * time_s)])
    expected = sosfiltfilt(butter(order, cutoff_Hz, fs=sample_Hz, output="sos"), series,
                           axis=0, padlen=pad)
    mine = zero_phase_lowpass(series, order, cutoff_Hz, sample_Hz, pad)
    assert mine.shape == series.shape
    # round-off of an FFT convolution: the worst case (poles 2e-4 of the sampling from
    # z = 1) measured 5e-11 of the series
    np.testing.assert_allclose(mine, expected, rtol=0, atol=1e-9 * np.abs(series).max())
    one = zero_phase_lowpass(series[:, 1], order, cutoff_Hz, sample_Hz, pad)
    np.testing.assert_allclose(one, mine[:, 1], rtol=0, atol=1e-12 * np.abs(series).max())


def test_a_constant_passes_unchanged_and_bad_settings_are_named():
    np.testing.assert_allclose(zero_phase_lowpass(np.full(50, 3.0), 4, 100.0, 1e4, 20), 3.0,
                               rtol=1e-13)
    with pytest.raises(ValueError, match="cutoff_Hz = 6000.0: must lie in"):
        zero_phase_lowpass(np.zeros(50), 4, 6000.0, 1e4, 10)
    with pytest.raises(ValueError, match="pad = 50: must lie in"):
        zero_phase_lowpass(np.zeros(50), 4, 100.0, 1e4, 50)
