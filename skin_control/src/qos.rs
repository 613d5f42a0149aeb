//! QoS profiles used across the nodes, named for what they carry. Publishers offer reliable
//! delivery; subscriptions ask for no more than their input needs (REP 2003), so that a driver's
//! best-effort sensor stream (SensorDataQoS) and an ordinary volatile goal publisher match.
use r2r::QosProfile;

/// Streams of sensor data and commands: reliable, a short history (a late sample is worth less
/// than the next one, but tests and bag replay must not lose samples to best-effort delivery).
pub fn stream() -> QosProfile {
    QosProfile::default().reliable().keep_last(10)
}

/// Streams whose every sample matters (the supervisor's dwell timers count controller states;
/// `/skin/cells` is event driven, a lost message would lose its cells' changes): a
/// deep reader history, so a node that is descheduled for a while (lockstep simulation runs the
/// graph several times faster than real time) catches up instead of losing samples; r2r takes
/// one sample per spin, so the reader history is the only buffer. A publisher of such a stream
/// keeps as deep a history: a reliable writer drops the samples a slow reader has not
/// acknowledged once they leave its history (the supervisor got 1887 of 2000 controller states
/// under load with a writer history of 10).
pub fn every_sample() -> QosProfile {
    QosProfile::default().reliable().keep_last(1000)
}

/// Sensor inputs (joint states, odometry, scan, skin cells): best effort, which matches both
/// best-effort (REP 2003's SensorDataQoS) and reliable publishers. A sample lost in transport
/// is not resent (the next one replaces it; the lockstep simulator resends a period that got no
/// answer). `depth`: the reader history, as in [`stream`] or [`every_sample`].
pub fn sensor_input(depth: usize) -> QosProfile {
    QosProfile::default().best_effort().keep_last(depth)
}

/// Commands and references a user sends (goals, force references): reliable and volatile,
/// which matches volatile publishers (`ros2 topic pub`, RViz's goal tool) and latched ones alike
/// (a volatile reader gets no history: a latched publisher's sample sent before it joined is
/// not delivered, so the simulator repeats the active goal).
pub fn user_input() -> QosProfile {
    QosProfile::default().reliable().volatile().keep_last(10)
}

/// State that a late joiner must still get (the active arrangement): reliable, transient local.
pub fn latched() -> QosProfile {
    QosProfile::default().reliable().keep_last(1).transient_local()
}

/// `/diagnostics`: reliable, volatile, keep last 1, as ROS 2's diagnostic_updater publishes it.
pub fn diagnostics() -> QosProfile {
    QosProfile::default().reliable().volatile().keep_last(1)
}

/// Services: the rmw default (reliable, volatile, keep last 10).
pub fn services() -> QosProfile {
    QosProfile::default()
}
