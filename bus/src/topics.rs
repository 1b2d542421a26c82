//! Topics, their QoS, and the per-run prefix: the one place where service
//! names and quality of service are decided.

use std::cell::Cell;
use std::fmt::Debug;
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::{Arc, OnceLock};
use std::time::Duration;

use iceoryx2::node::NodeWaitFailure;
use iceoryx2::port::BackpressureAction;
use iceoryx2::port::SendError;
use iceoryx2::port::listener::{Listener, ListenerWaitError};
use iceoryx2::port::notifier::Notifier;
use iceoryx2::port::publisher::Publisher;
use iceoryx2::port::subscriber::Subscriber;

use crate::connections::{CONNECTION_FAILED, degraded};
use iceoryx2::prelude::*;
use wire::{
    Bound, Delivery, Header, LOSSLESS_TIMEOUT, MAX_NODES, MAX_SUBSCRIBERS, MessageFields,
    SUBSCRIBER_BUFFER, Topic,
};

/// Why a bus operation failed.
#[derive(Debug, thiserror::Error)]
pub enum BusError {
    /// The prefix is not a valid file-name fragment.
    #[error("invalid run prefix '{0}': use letters, digits, '_' or '-' (at most 40)")]
    BadPrefix(String),
    /// iceoryx2 refused something.
    #[error("{what} ({topic}): {cause}")]
    Ipc {
        /// What was attempted.
        what: &'static str,
        /// The topic or node.
        topic: String,
        /// iceoryx2's error.
        cause: String,
    },
    /// A SIGINT or SIGTERM arrived.
    #[error("interrupted by a termination request")]
    Terminated,
}

fn ipc(what: &'static str, topic: impl Into<String>) -> impl FnOnce(String) -> BusError {
    let topic = topic.into();
    move |cause| BusError::Ipc { what, topic, cause }
}

/// The prefix that keeps one run's shared memory apart from every other's.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct RunPrefix(String);

impl RunPrefix {
    /// The prefix every testbed run starts with (used to find stale runs).
    pub const STEM: &'static str = wire::RUN_PREFIX_STEM;

    /// A prefix no other run on this machine uses: process id and start time.
    pub fn unique() -> Self {
        let nanos = std::time::SystemTime::now()
            .duration_since(std::time::UNIX_EPOCH)
            .map_or(0, |d| d.as_nanos());
        Self(format!(
            "{}{:x}x{:x}_",
            Self::STEM,
            std::process::id(),
            nanos & 0xffff_ffff_ffff
        ))
    }

    /// The pid of the launcher that made this prefix ([`RunPrefix::unique`]).
    pub fn launcher_pid(&self) -> Option<u32> {
        let rest = self.0.strip_prefix(Self::STEM)?;
        let (pid, _) = rest.split_once('x')?;
        u32::from_str_radix(pid, 16).ok()
    }

    /// Checks a prefix given on a command line.
    pub fn parse(s: &str) -> Result<Self, BusError> {
        let ok = !s.is_empty()
            && s.len() <= 40
            && s.chars()
                .all(|c| c.is_ascii_alphanumeric() || c == '_' || c == '-');
        if ok {
            Ok(Self(s.to_string()))
        } else {
            Err(BusError::BadPrefix(s.to_string()))
        }
    }

    /// The prefix text.
    pub fn as_str(&self) -> &str {
        &self.0
    }

    /// Takes write access from other users on this run's files in
    /// /dev/shm: iceoryx2 makes its `global_mgmt` file writable by anyone
    /// (0666), and every process of a run is the same user. Best effort: a
    /// file that is not ours, or gone, is left as it is.
    fn close_shared_files(&self) {
        use std::os::unix::fs::PermissionsExt;
        let Ok(dir) = std::fs::read_dir("/dev/shm") else {
            return;
        };
        for entry in dir.flatten() {
            let name = entry.file_name();
            if !name.to_string_lossy().starts_with(self.as_str()) {
                continue;
            }
            if let Ok(meta) = entry.metadata()
                && meta.permissions().mode() & 0o022 != 0
            {
                let mode = meta.permissions().mode() & !0o022;
                let _ =
                    std::fs::set_permissions(entry.path(), std::fs::Permissions::from_mode(mode));
            }
        }
    }

    /// The iceoryx2 configuration for this run.
    pub fn config(&self) -> Result<Config, BusError> {
        let mut config = Config::default();
        config.global.prefix = FileName::new(self.0.as_bytes())
            .map_err(|e| ipc("prefix", self.0.clone())(format!("{e:?}")))?;
        Ok(config)
    }
}

/// CLOCK_MONOTONIC in nanoseconds: the wall clock every process shares.
pub fn monotonic_ns() -> u64 {
    match nix::time::clock_gettime(nix::time::ClockId::CLOCK_MONOTONIC) {
        Ok(ts) => ts.tv_sec() as u64 * 1_000_000_000 + ts.tv_nsec() as u64,
        Err(_) => 0,
    }
}

/// One process's connection to a run: an iceoryx2 node under the run prefix.
pub struct Bus {
    node: Node<ipc::Service>,
    prefix: RunPrefix,
}

impl Debug for Bus {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "Bus({})", self.prefix.as_str())
    }
}

/// A publisher with its notifier and a sequence counter.
pub struct TopicPublisher<T: Debug + ZeroCopySend + MessageFields + 'static> {
    topic: Topic,
    publisher: Publisher<ipc::Service, T, ()>,
    /// None on topics without waiters.
    notifier: Option<Notifier<ipc::Service>>,
    /// The service, to count its subscribers, when every one must get
    /// every sample (lossless).
    lossless: Option<PubSubService<T>>,
}

type PubSubService<T> =
    iceoryx2::service::port_factory::publish_subscribe::PortFactory<ipc::Service, T, ()>;

/// A subscriber, with its listener unless it is read by polling.
pub struct TopicSubscriber<T: Debug + ZeroCopySend + MessageFields + 'static> {
    topic: Topic,
    subscriber: Subscriber<ipc::Service, T, ()>,
    listener: Option<Listener<ipc::Service>>,
    /// The header of the last sample passed on, to drop a resent copy.
    last: Cell<Option<Header>>,
}

/// Tries of one send that a signal interrupted ([`TopicPublisher::send`]).
const SEND_ATTEMPTS: u32 = 3;

/// SIGINT or SIGTERM seen by this process, kept by a handler of our own:
/// iceoryx2 keeps only the last signal and clears it before some calls
/// (zeroing a new segment, a listener's wait), so a Ctrl-C during start-up
/// could be lost. Registered once the first node exists, after iceoryx2's
/// own handler, which is still called.
fn terminated() -> &'static AtomicBool {
    static FLAG: OnceLock<Arc<AtomicBool>> = OnceLock::new();
    FLAG.get_or_init(|| {
        let flag = Arc::new(AtomicBool::new(false));
        for sig in [signal_hook::consts::SIGINT, signal_hook::consts::SIGTERM] {
            // Without it only iceoryx2's flag remains: worse, not fatal.
            let _ = signal_hook::flag::register(sig, Arc::clone(&flag));
        }
        flag
    })
}

impl Bus {
    /// Creates this process's node; `name` appears in iceoryx2's node list.
    pub fn new(prefix: &RunPrefix, name: &str) -> Result<Self, BusError> {
        let config = prefix.config()?;
        let node_name =
            NodeName::new(name).map_err(|e| ipc("node name", name)(format!("{e:?}")))?;
        let node = NodeBuilder::new()
            .name(&node_name)
            .config(&config)
            .create::<ipc::Service>()
            .map_err(|e| ipc("create node", name)(format!("{e:?}")))?;
        terminated();
        prefix.close_shared_files();
        Ok(Self {
            node,
            prefix: prefix.clone(),
        })
    }

    /// Sleeps up to `timeout`; `Err(Terminated)` once SIGINT or SIGTERM arrived.
    pub fn wait(&self, timeout: Duration) -> Result<(), BusError> {
        if terminated().load(Ordering::Relaxed) {
            return Err(BusError::Terminated);
        }
        match self.node.wait(timeout) {
            Ok(()) => Ok(()),
            Err(NodeWaitFailure::TerminationRequest) => Err(BusError::Terminated),
            // A signal cut the sleep short: Ctrl-C shows as a termination
            // request on a second, zero wait; anything else (SIGCONT after
            // Ctrl-Z and `fg`, a paused VM) is only an early wake-up.
            Err(NodeWaitFailure::Interrupt) => match self.node.wait(Duration::ZERO) {
                Err(NodeWaitFailure::TerminationRequest) => Err(BusError::Terminated),
                _ => Ok(()),
            },
        }
    }

    fn service<T: Debug + ZeroCopySend + MessageFields + 'static>(
        &self,
        topic: Topic,
    ) -> Result<
        iceoryx2::service::port_factory::publish_subscribe::PortFactory<ipc::Service, T, ()>,
        BusError,
    > {
        let name: ServiceName = topic
            .name()
            .try_into()
            .map_err(|e| ipc("service name", topic.name())(format!("{e:?}")))?;
        // Never overwrite: a full buffer makes the publisher wait (lossless)
        // or skip that reader (drop), both visible, never a silent loss.
        self.node
            .service_builder(&name)
            .publish_subscribe::<T>()
            .enable_safe_overflow(false)
            .history_size(0)
            .subscriber_max_buffer_size(SUBSCRIBER_BUFFER)
            .max_publishers(topic.max_publishers())
            .max_subscribers(MAX_SUBSCRIBERS)
            .max_nodes(MAX_NODES)
            .open_or_create()
            .map_err(|e| ipc("open topic", topic.name())(format!("{e:?}")))
    }

    fn event(
        &self,
        topic: Topic,
    ) -> Result<iceoryx2::service::port_factory::event::PortFactory<ipc::Service>, BusError> {
        let name: ServiceName = topic
            .name()
            .try_into()
            .map_err(|e| ipc("service name", topic.name())(format!("{e:?}")))?;
        self.node
            .service_builder(&name)
            .event()
            .max_notifiers(topic.max_notifiers())
            .max_listeners(MAX_SUBSCRIBERS)
            .max_nodes(MAX_NODES)
            .open_or_create()
            .map_err(|e| ipc("open event", topic.name())(format!("{e:?}")))
    }

    /// A publisher of `T` on its topic ([`wire::Bound::TOPIC`]): the
    /// message type alone says where it goes.
    pub fn publisher<T: Debug + ZeroCopySend + Bound + 'static>(
        &self,
        delivery: Delivery,
    ) -> Result<TopicPublisher<T>, BusError> {
        let topic = T::TOPIC;
        let service = self.service::<T>(topic)?;
        let builder = service
            .publisher_builder()
            .set_degradation_handler(move |c, i| degraded(topic, c, i));
        let builder = match delivery {
            Delivery::Lossless => builder
                .backpressure_strategy(BackpressureStrategy::RetryUntilDelivered)
                .set_backpressure_handler(|info: &iceoryx2::port::BackpressureInfo| {
                    if info.elapsed_time < LOSSLESS_TIMEOUT {
                        BackpressureAction::Retry
                    } else {
                        BackpressureAction::DiscardDataAndFail
                    }
                }),
            Delivery::DropWhenFull => {
                builder.backpressure_strategy(BackpressureStrategy::DiscardData)
            }
        };
        let publisher = builder
            .create()
            .map_err(|e| ipc("create publisher", topic.name())(format!("{e:?}")))?;
        let notifier = if topic.has_waiters() {
            Some(
                self.event(topic)?
                    .notifier_builder()
                    .create()
                    .map_err(|e| ipc("create notifier", topic.name())(format!("{e:?}")))?,
            )
        } else {
            None
        };
        Ok(TopicPublisher {
            topic,
            publisher,
            notifier,
            lossless: (delivery == Delivery::Lossless).then_some(service),
        })
    }

    /// A subscriber of `T` on its topic that can block until a sample arrives
    /// ([`TopicSubscriber::wait_event`]); only topics with waiters have
    /// wake-ups ([`Topic::has_waiters`]).
    pub fn subscriber<T: Debug + ZeroCopySend + Bound + 'static>(
        &self,
    ) -> Result<TopicSubscriber<T>, BusError> {
        self.subscriber_with(T::TOPIC, T::TOPIC.has_waiters())
    }

    /// A subscriber read by polling: no listener, so publishers do not wake it.
    pub fn polling_subscriber<T: Debug + ZeroCopySend + Bound + 'static>(
        &self,
    ) -> Result<TopicSubscriber<T>, BusError> {
        self.subscriber_with(T::TOPIC, false)
    }

    fn subscriber_with<T: Debug + ZeroCopySend + MessageFields + 'static>(
        &self,
        topic: Topic,
        listen: bool,
    ) -> Result<TopicSubscriber<T>, BusError> {
        let service = self.service::<T>(topic)?;
        let subscriber = service
            .subscriber_builder()
            .buffer_size(SUBSCRIBER_BUFFER)
            .set_degradation_handler(move |c, i| degraded(topic, c, i))
            .create()
            .map_err(|e| ipc("create subscriber", topic.name())(format!("{e:?}")))?;
        let listener = if listen {
            Some(
                self.event(topic)?
                    .listener_builder()
                    .create()
                    .map_err(|e| ipc("create listener", topic.name())(format!("{e:?}")))?,
            )
        } else {
            None
        };
        Ok(TopicSubscriber {
            topic,
            subscriber,
            listener,
            last: Cell::new(None),
        })
    }
}

impl<T: Debug + ZeroCopySend + MessageFields + 'static> TopicPublisher<T> {
    /// Publishes `value` and wakes the listeners. Returns how many
    /// subscribers received it.
    pub fn send(&self, value: T) -> Result<usize, BusError> {
        let mut attempt = 1;
        let delivered = loop {
            let sample = self
                .publisher
                .loan_uninit()
                .map_err(|e| ipc("loan", self.topic.name())(format!("{e:?}")))?;
            match sample.write_payload(value).send() {
                Ok(n) => break n,
                // A lossless send waiting for room is cut short by a signal
                // (Ctrl-Z and `fg`): iceoryx2 gives up with the sample
                // delivered to some readers only. Sent again, the readers
                // that have it drop the copy ([`TopicSubscriber::receive`]).
                Err(SendError::InternalError) if attempt < SEND_ATTEMPTS => attempt += 1,
                Err(e) => return Err(ipc("send", self.topic.name())(format!("{e:?}"))),
            }
        };
        if let Some(service) = &self.lossless {
            // A subscriber registered but not connected would miss every
            // sample without a word (iceoryx2 sometimes leaves a pair
            // unconnected when a run starts): a transport failure.
            let subscribers = service.dynamic_config().number_of_subscribers();
            if delivered < subscribers {
                return Err(ipc("send", self.topic.name())(format!(
                    "{CONNECTION_FAILED}: a sample reached {delivered} of {subscribers} subscribers"
                )));
            }
        }
        if let Some(n) = &self.notifier {
            n.notify()
                .map_err(|e| ipc("notify", self.topic.name())(format!("{e:?}")))?;
        }
        Ok(delivered)
    }
}

impl<T: Debug + ZeroCopySend + MessageFields + 'static> TopicSubscriber<T> {
    /// The next buffered sample, if any; a copy of the sample before it
    /// (same header: a send that was interrupted and made again) is dropped.
    pub fn receive(&self) -> Result<Option<T>, BusError> {
        loop {
            match self.subscriber.receive() {
                Ok(Some(sample)) => {
                    let header = MessageFields::header(&*sample);
                    if self.last.replace(Some(header)) != Some(header) {
                        return Ok(Some(*sample));
                    }
                }
                Ok(None) => return Ok(None),
                Err(e) => return Err(ipc("receive", self.topic.name())(format!("{e:?}"))),
            }
        }
    }

    /// Consumes pending wake-ups (a WaitSet spins until they are drained).
    pub fn drain_events(&self) -> Result<(), BusError> {
        match &self.listener {
            Some(l) => l
                .try_wait(|_| {})
                .map(|_| ())
                .map_err(|e| ipc("listener", self.topic.name())(format!("{e:?}"))),
            None => Ok(()),
        }
    }

    /// Blocks until a wake-up arrives or `timeout` passes; true if one
    /// arrived. A polling subscriber has no wake-ups: it sleeps for `timeout`.
    pub fn wait_event(&self, timeout: Duration) -> Result<bool, BusError> {
        match &self.listener {
            Some(l) => {
                let mut woken = false;
                match l.timed_wait(|_| woken = true, timeout) {
                    // A signal woke the wait (Ctrl-Z then `fg`): an early
                    // wake-up; termination is the caller's `check` to see.
                    Ok(_) | Err(ListenerWaitError::InterruptSignal) => Ok(woken),
                    Err(e) => Err(ipc("listener", self.topic.name())(format!("{e:?}"))),
                }
            }
            None => {
                std::thread::sleep(timeout);
                Ok(false)
            }
        }
    }
}

#[cfg(test)]
mod tests {
    #![allow(
        clippy::unwrap_used,
        reason = "test code: a broken expectation should fail loudly"
    )]
    use super::*;
    use wire::Timing;

    /// A sample sent again after an interrupted send reaches each reader
    /// once; a different sample right after it still arrives.
    #[test]
    fn a_resent_sample_is_received_once() {
        let prefix = RunPrefix::unique();
        let bus = Bus::new(&prefix, "resend-test").unwrap();
        let publisher = bus.publisher::<Timing>(Delivery::Lossless).unwrap();
        let subscriber = bus.polling_subscriber::<Timing>().unwrap();
        let sample = |seq| Timing {
            header: Header {
                seq,
                t_ns: seq * 1000,
                wall_ns: 77,
            },
            ..Timing::default()
        };
        for s in [sample(1), sample(1), sample(2)] {
            publisher.send(s).unwrap();
        }
        let got: Vec<u64> = std::iter::from_fn(|| subscriber.receive().unwrap())
            .map(|t| t.header.seq)
            .collect();
        assert_eq!(got, [1, 2]);
        drop((publisher, subscriber, bus));
        let _ = prefix.remove_domain_if_unused();
        prefix.remove_leftover_files(true);
    }
}
