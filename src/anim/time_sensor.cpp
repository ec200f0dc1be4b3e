#include "anim/time_sensor.h"

#include <cmath>

namespace vr {
namespace {

// Events of an active sensor at time t (t >= start_time).
TimeSensorState running(const TimeSensorFields& s, double t) {
    TimeSensorState state;
    state.sent = true;
    state.time = t;
    const double elapsed = t - s.start_time;
    double cycles = std::floor(elapsed / s.cycle_interval);
    double f = elapsed - cycles * s.cycle_interval;  // fmod, but with the cycle count known
    if (f < 0.0) f = 0.0;                            // rounding of the floor
    if (f == 0.0 && elapsed > 0.0) {
        state.fraction = 1.0;
        cycles -= 1.0;
    } else {
        state.fraction = f / s.cycle_interval;
    }
    state.cycle_time = s.start_time + std::fmax(cycles, 0.0) * s.cycle_interval;
    return state;
}

}  // namespace

TimeSensorState time_sensor_at(const TimeSensorFields& s, double now) {
    TimeSensorState none;
    if (!s.enabled || !(s.cycle_interval > 0.0) || !std::isfinite(s.cycle_interval) ||
        !std::isfinite(now) || now < s.start_time)
        return none;
    // When it stops: the end of its one cycle, or stopTime when that comes after startTime.
    double stop = INFINITY;
    if (!s.loop) stop = s.start_time + s.cycle_interval;
    if (s.stop_time > s.start_time) stop = std::fmin(stop, s.stop_time);
    // A run over before the world began (its clock starts at 0) was never active in it: a
    // browser sends no event for it, so the fields it drives keep their file values.
    if (stop <= kWorldLoadTime) return none;
    if (now < stop) {
        TimeSensorState state = running(s, now);
        state.active = true;
        return state;
    }
    TimeSensorState state = running(s, stop);  // the events of the stopping moment
    state.active = false;
    return state;
}

}  // namespace vr
