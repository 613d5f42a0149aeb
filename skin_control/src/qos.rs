//! QoS profiles used across the nodes, named for what they carry.
use r2r::QosProfile;

/// Streams of sensor data and commands: reliable, a short history (a late sample is worth less
/// than the next one, but tests and bag replay must not lose samples to best-effort delivery).
pub fn stream() -> QosProfile {
    QosProfile::default().reliable().keep_last(10)
}

/// Inputs whose every sample matters (the supervisor's dwell timers count controller states;
/// `/skin/cells` is event driven, a lost message would lose its cells' changes): a
/// deep reader history, so a node that is descheduled for a while (lockstep simulation runs the
/// graph several times faster than real time) catches up instead of losing samples; r2r takes
/// one sample per spin, so the reader history is the only buffer.
pub fn every_sample() -> QosProfile {
    QosProfile::default().reliable().keep_last(1000)
}

/// State that a late joiner must still get (the active arrangement): reliable, transient local.
pub fn latched() -> QosProfile {
    QosProfile::default().reliable().keep_last(1).transient_local()
}

/// Services: the rmw default (reliable, volatile, keep last 10).
pub fn services() -> QosProfile {
    QosProfile::default()
}
