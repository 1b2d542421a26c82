//! The live view's server: the `foxglove` crate's WebSocket server on its
//! own tokio runtime, started only for a run with `--live`.
//!
//! The run must not wait for a viewer. Each topic goes out live at most
//! `rate_hz` times per second of sim time (every k-th sample: which ones is
//! deterministic); a topic nobody subscribes to costs one check. The server
//! queues each client's messages and drops the oldest when a client falls
//! behind, so a client that never reads costs the logger a bounded queue;
//! once its control queue (the clock's ticks among them) is full too, the
//! server disconnects it. How many of a client's messages the server
//! dropped, foxglove 0.30 does not tell (its `ConnectedClient::log` throws
//! the count away); what the stats record per client is what was handed to
//! the server for it, and how many topics it was subscribed to at the end
//! (a client that left, or that the server disconnected, is counted among
//! those gone).

use std::collections::{BTreeMap, HashMap, HashSet};
use std::sync::{Arc, Mutex};

use super::front::Front;
use super::{LiveConfig, LiveError, LiveView};
use crate::ChannelSpec;
use foxglove::websocket::{Capability, ChannelView, Client, ClientId, ServerListener};
use foxglove::{ChannelId, Context, PartialMetadata, RawChannel, Schema, WebSocketServerHandle};

/// Messages the server queues per client before dropping the oldest
/// (≈ 3 s of every topic at the default rate).
const BACKLOG: usize = 1024;

/// How long the logger waits for the clients' close frames at the end.
const STOP_WAIT: std::time::Duration = std::time::Duration::from_millis(500);

/// One channel as served live.
struct LiveTopic {
    name: &'static str,
    channel: Arc<RawChannel>,
    next_ns: u64,
    sent: u64,
}

/// Who is connected and what they subscribed to, kept by the server's
/// callbacks (its own threads), read by the logger.
#[derive(Default)]
struct ClientBook(Mutex<Book<ClientId>>);

/// The clients by id: an entry from a client's first subscription until it
/// disconnects, when its count joins the totals of those gone, so that the
/// book holds the clients connected now, not every one that ever came (30
/// reconnecting viewers once left thousands of entries).
struct Book<K> {
    /// Clients that ever subscribed; a client's number is its place here.
    ever: u64,
    clients: HashMap<K, ClientCount>,
    /// Clients gone, and the messages handed to the server for them.
    gone: u64,
    gone_messages: u64,
}

impl<K> Default for Book<K> {
    fn default() -> Self {
        Self {
            ever: 0,
            clients: HashMap::new(),
            gone: 0,
            gone_messages: 0,
        }
    }
}

struct ClientCount {
    /// 1 for the first client that subscribed, and so on.
    number: u64,
    channels: HashSet<ChannelId>,
    /// Messages handed to the server for this client.
    messages: u64,
}

impl<K: Eq + std::hash::Hash> Book<K> {
    fn subscribe(&mut self, client: K, channel: ChannelId) {
        let ever = &mut self.ever;
        let entry = self.clients.entry(client).or_insert_with(|| {
            *ever += 1;
            ClientCount {
                number: *ever,
                channels: HashSet::new(),
                messages: 0,
            }
        });
        entry.channels.insert(channel);
    }

    fn unsubscribe(&mut self, client: &K, channel: ChannelId) {
        if let Some(c) = self.clients.get_mut(client) {
            c.channels.remove(&channel);
        }
    }

    /// A client disconnected. The server unsubscribes each of its channels
    /// first but does not say which client went: every client without a
    /// subscription is taken as gone (one still connected that subscribes
    /// again is then counted as a new client).
    fn disconnected(&mut self) {
        let (mut gone, mut messages) = (0, 0);
        self.clients.retain(|_, c| {
            let keep = !c.channels.is_empty();
            if !keep {
                gone += 1;
                messages += c.messages;
            }
            keep
        });
        self.gone += gone;
        self.gone_messages += messages;
    }

    fn count(&mut self, channel: ChannelId) {
        for c in self.clients.values_mut() {
            if c.channels.contains(&channel) {
                c.messages += 1;
            }
        }
    }

    /// The book's entries in the log's stats.
    fn stats(&self, out: &mut BTreeMap<String, String>) {
        out.insert("live.clients".into(), self.ever.to_string());
        out.insert("live.clients_gone".into(), self.gone.to_string());
        out.insert(
            "live.clients_gone.messages".into(),
            self.gone_messages.to_string(),
        );
        for c in self.clients.values() {
            let client = format!("live.client{}", c.number);
            out.insert(format!("{client}.messages"), c.messages.to_string());
            out.insert(
                format!("{client}.subscribed_at_end"),
                c.channels.len().to_string(),
            );
        }
    }
}

impl ClientBook {
    fn book(&self) -> std::sync::MutexGuard<'_, Book<ClientId>> {
        // A poisoned lock only means a callback panicked mid-count: the
        // counts are still the best there are.
        self.0.lock().unwrap_or_else(|e| e.into_inner())
    }

    fn count(&self, channel: ChannelId) {
        self.book().count(channel);
    }
}

impl ServerListener for ClientBook {
    fn on_subscribe(&self, client: Client, channel: ChannelView) {
        self.book().subscribe(client.id(), channel.id());
    }

    fn on_unsubscribe(&self, client: Client, channel: ChannelView) {
        self.book().unsubscribe(&client.id(), channel.id());
    }

    fn on_client_disconnect(&self) {
        self.book().disconnected();
    }
}

/// The running live view.
pub(super) struct Live {
    /// Holds the channels and the server's sinks: both go with it.
    _context: Arc<Context>,
    server: Option<WebSocketServerHandle>,
    /// The relay on the user's address (client limit, subprotocol names).
    front: Option<Front>,
    topics: Vec<LiveTopic>,
    period_ns: u64,
    book: Arc<ClientBook>,
    config: LiveConfig,
    /// The topic whose samples set the viewer's clock.
    clock_topic: &'static str,
}

impl Live {
    /// Starts the server on `config.addr` with `channels` (the first one's
    /// samples drive the viewer's clock).
    pub(super) fn start(config: &LiveConfig, channels: &[ChannelSpec]) -> Result<Self, LiveError> {
        let ctx = Context::new();
        let book = Arc::new(ClientBook::default());
        let addr = config.addr;
        let server = ctx
            .websocket_server()
            .name(format!("testbed {}", env!("CARGO_PKG_VERSION")))
            // Loopback only: clients come through the front relay.
            .bind("127.0.0.1", 0)
            .capabilities([Capability::Time])
            .message_backlog_size(BACKLOG)
            .listener(book.clone())
            .start_blocking()
            .map_err(|e| LiveError::Listen {
                addr,
                cause: e.to_string(),
            })?;
        let topics = channels
            .iter()
            .map(|spec| open(&ctx, spec))
            .collect::<Result<Vec<_>, _>>()?;
        let inner = std::net::SocketAddr::from(([127, 0, 0, 1], server.port()));
        let front =
            Front::start(addr, inner, config.max_clients).map_err(|e| LiveError::Listen {
                addr,
                cause: e.to_string(),
            })?;
        // Port 0 asks the system for one: record the one it gave.
        let bound = front.address();
        Ok(Self {
            _context: ctx,
            server: Some(server),
            front: Some(front),
            topics,
            period_ns: (1e9 / config.rate_hz) as u64,
            book,
            config: LiveConfig {
                addr: bound,
                ..config.clone()
            },
            clock_topic: channels.first().map_or("", |c| c.topic),
        })
    }

    /// The counts, taken while the clients are still connected.
    fn stats(&self) -> BTreeMap<String, String> {
        let mut out = BTreeMap::new();
        out.insert("live.address".into(), self.config.addr.to_string());
        out.insert("live.rate_hz".into(), format!("{:?}", self.config.rate_hz));
        out.insert(
            "live.max_clients".into(),
            self.config.max_clients.to_string(),
        );
        if let Some(front) = &self.front {
            let (refused, accepted) = front.counts();
            out.insert("live.connections".into(), accepted.to_string());
            out.insert("live.refused_clients".into(), refused.to_string());
            out.insert("live.bypass_cut".into(), front.bypassed().to_string());
        }
        for t in &self.topics {
            let name = t.name.trim_start_matches('/');
            out.insert(format!("live.{name}.sent"), t.sent.to_string());
        }
        self.book.book().stats(&mut out);
        out
    }
}

impl LiveView for Live {
    fn address(&self) -> std::net::SocketAddr {
        self.config.addr
    }

    fn offer(&mut self, topic: &str, t_ns: u64, data: &[u8]) {
        let Some(t) = self.topics.iter_mut().find(|t| t.name == topic) else {
            return;
        };
        if t_ns < t.next_ns {
            return;
        }
        t.next_ns = t_ns.saturating_add(self.period_ns);
        if topic == self.clock_topic
            && let Some(server) = &self.server
        {
            server.broadcast_time(t_ns);
        }
        if !t.channel.has_sinks() {
            return;
        }
        t.channel
            .log_with_meta(data, PartialMetadata::with_log_time(t_ns));
        t.sent += 1;
        self.book.count(t.channel.id());
    }

    fn finish(mut self: Box<Self>) -> BTreeMap<String, String> {
        let out = self.stats();
        if let Some(server) = self.server.take() {
            // A graceful stop sends each client a close frame; a client that
            // does not read may never let it through, so the logger waits
            // for it a moment only (the process then ends, and with it the
            // connections).
            let stopping = server.stop();
            let (done, stopped) = std::sync::mpsc::channel();
            std::thread::spawn(move || {
                stopping.wait_blocking();
                let _ = done.send(());
            });
            let _ = stopped.recv_timeout(STOP_WAIT);
        }
        if let Some(front) = self.front.take() {
            front.stop();
        }
        out
    }
}

fn open(ctx: &Arc<Context>, spec: &ChannelSpec) -> Result<LiveTopic, LiveError> {
    let err = |cause: String| LiveError::Channel {
        topic: spec.topic,
        cause,
    };
    let channel = ctx
        .channel_builder(spec.topic)
        .message_encoding(crate::MESSAGE_ENCODING)
        .schema(Schema::new(
            spec.schema_name.as_str(),
            crate::SCHEMA_ENCODING,
            spec.schema.as_bytes().to_vec(),
        ))
        .build_raw()
        .map_err(|e| err(e.to_string()))?;
    Ok(LiveTopic {
        name: spec.topic,
        channel,
        next_ns: 0,
        sent: 0,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    /// #48 item 16: the book drops a client that disconnected (its count
    /// kept in the totals), so reconnecting viewers do not grow it; the
    /// clients still there keep their numbers.
    #[test]
    fn a_client_that_left_leaves_the_book() {
        let mut book: Book<u32> = Book::default();
        let (a, b) = (ChannelId::new(1), ChannelId::new(2));
        book.subscribe(7, a);
        book.subscribe(7, b);
        for round in 0..1000 {
            book.subscribe(round + 100, a);
            book.count(a);
            // The server unsubscribes every channel of a client that
            // disconnects, then says a client went.
            book.unsubscribe(&(round + 100), a);
            book.disconnected();
            assert_eq!(book.clients.len(), 1, "round {round}");
        }
        assert_eq!(
            (book.ever, book.gone, book.gone_messages),
            (1001, 1000, 1000)
        );
        let mut out = BTreeMap::new();
        book.stats(&mut out);
        assert_eq!(out["live.clients"], "1001");
        assert_eq!(out["live.clients_gone"], "1000");
        assert_eq!(out["live.client1.messages"], "1000");
        assert_eq!(out["live.client1.subscribed_at_end"], "2");
        assert_eq!(out.len(), 5, "{out:?}");
    }
}
