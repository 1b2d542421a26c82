//! What the testbed does when iceoryx2 cannot connect two ports. By
//! default iceoryx2 only warns, below the log level the nodes run at, and
//! the port never retries: every sample on that pair would be lost without
//! a word. Here it is said on stderr, counted, and the send or receive that
//! found it fails; the launcher starts such a run again.

use std::sync::atomic::{AtomicU64, Ordering};

use iceoryx2::port::{DegradationAction, DegradationCause, DegradationInfo};

use wire::Topic;

/// What a node says on stderr when iceoryx2 cannot connect two ports: the
/// launcher starts the run again when a node's last words hold it.
pub const CONNECTION_FAILED: &str = "iceoryx2 could not connect";

static CONNECTION_FAILURES: AtomicU64 = AtomicU64::new(0);

/// Connections iceoryx2 could not make in this process so far (one made
/// while a port is created only warns inside iceoryx2, and that port then
/// never retries it: [`crate::NodeLink`] fails the node at READY).
pub fn connection_failures() -> u64 {
    CONNECTION_FAILURES.load(Ordering::Relaxed)
}

/// A connection iceoryx2 could not make or found corrupted: said on stderr
/// whatever iceoryx2's log level (by default it only warns, and samples on
/// that connection would be lost without a word), and the send or receive
/// that found it fails.
pub(crate) fn degraded(
    topic: Topic,
    cause: DegradationCause,
    info: &DegradationInfo,
) -> DegradationAction {
    let what = match cause {
        DegradationCause::FailedToEstablishConnection => {
            CONNECTION_FAILURES.fetch_add(1, Ordering::Relaxed);
            CONNECTION_FAILED
        }
        DegradationCause::ConnectionCorrupted => "iceoryx2 found a corrupted connection between",
    };
    eprintln!(
        "testbed: {what} publisher {:x} and subscriber {:x} of {}",
        info.sender_port_id,
        info.receiver_port_id,
        topic.name()
    );
    DegradationAction::DegradeAndFail
}
