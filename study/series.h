// Reading a physical answer off a sampled time series: an acceleration, an oscillation
// period, the time a series passes a level. The accuracy study (study/) measures its
// reference problems with these, from values a run wrote once per frame.
#pragma once
#include <optional>
#include <vector>

namespace shellmpm {

/// Least-squares fit of s(t) = s0 + v0 t + a t^2 / 2 over the samples; returns a.
/// @param t sample times [s], at least 3 distinct
/// @param s positions [m], same length as t
/// @throws std::invalid_argument with fewer than 3 samples or a singular fit
double fit_acceleration(const std::vector<double>& t, const std::vector<double>& s);

/// Least-squares slope of v(t) = v0 + a t; at least 2 distinct times.
double fit_slope(const std::vector<double>& t, const std::vector<double>& v);

/// Period of an oscillation about its mean: the mean spacing of same-direction crossings of
/// the mean (linear interpolation between samples), from the first to the last crossing.
/// Returns nothing with fewer than two upward (or two downward) crossings.
std::optional<double> oscillation_period(const std::vector<double>& t,
                                         const std::vector<double>& s);

/// The first time s(t) reaches `level` going in the direction of `rising` (linear
/// interpolation between samples); nothing when it never does.
std::optional<double> first_crossing(const std::vector<double>& t, const std::vector<double>& s,
                                     double level, bool rising);

}  // namespace shellmpm
