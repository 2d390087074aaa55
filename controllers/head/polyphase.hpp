#pragma once
// Resampling by a rational ratio with a polyphase windowed-sinc filter: a
// table of filter phases computed once, then one short dot product per
// output sample. Many times faster than libsamplerate's sinc converters
// (which interpolate their filter for every sample), and ample for pitch
// and energy: passband to 90 % of the lower Nyquist frequency, Kaiser
// window (beta 8.6, about 85 dB stopband).

#include <span>
#include <vector>

namespace animrt::head {

// `in` at in_rate to `out` at out_rate (output sample n at input position
// n * in_rate / out_rate, as libsamplerate places it). False, `out`
// untouched, when the reduced ratio's terms are too large for a table (the
// caller uses another converter).
bool resample_polyphase(std::span<const float> in, int in_rate, int out_rate,
                        std::vector<float>& out);

}  // namespace animrt::head
