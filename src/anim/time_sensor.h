// What a TimeSensor (VRML97 6.50, X3D 8.4.1) has sent by the time the world's clock reads `now`:
// the clock starts at 0 when the file is loaded (docs/animation.md), so startTime counts from
// there.
#pragma once

namespace vr {

// The world's clock at the moment the file is loaded.
inline constexpr double kWorldLoadTime = 0.0;

struct TimeSensorFields {
    double cycle_interval = 1.0;  // > 0, else the sensor never runs
    bool enabled = true;
    bool loop = false;
    double start_time = 0.0;
    double stop_time = 0.0;  // ignored when <= start_time
};

struct TimeSensorState {
    bool sent = false;      // false: no event yet (before startTime, disabled): fields keep values
    bool active = false;    // isActive's last value
    double fraction = 0.0;  // fraction_changed's last value
    double time = 0.0;      // the last `time` event: now while active, else when it stopped
    double cycle_time = 0.0;  // the start of the cycle the last events belong to
};

// The last events a sensor with `fields` has sent at or before `now`. While active: fraction =
// f / cycleInterval with f = fmod(now - startTime, cycleInterval), except that f = 0 after the
// start reads 1 (the end of a cycle, not the start of the next). A sensor that has stopped (at
// startTime + cycleInterval without loop, or at a stopTime > startTime) keeps the events of the
// moment it stopped; one that stopped before the world was loaded has sent nothing.
TimeSensorState time_sensor_at(const TimeSensorFields& fields, double now);

}  // namespace vr
