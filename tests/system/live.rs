//! `testbed run --live`: a WebSocket client here connects as the Foxglove
//! app does (protocol `foxglove.sdk.v1`), subscribes, and checks what
//! arrives against what the log keeps.

use std::collections::{BTreeMap, HashMap};
use std::net::{TcpListener, TcpStream};
use std::path::Path;
use std::process::{Child, Stdio};
use std::time::{Duration, Instant};

use serde_json::{Value, json};
use tungstenite::client::IntoClientRequest;
use tungstenite::{Message, WebSocket};

use crate::util::{ended, fails, testbed, wait_for_nodes};

/// A port free a moment ago (the launcher refuses it, named, if taken since).
fn free_port() -> u16 {
    TcpListener::bind("127.0.0.1:0")
        .unwrap()
        .local_addr()
        .unwrap()
        .port()
}

/// The subprotocol Foxglove's app offers.
const SDK: &str = "foxglove.sdk.v1";
/// The name in the ws-protocol specification (npm `@foxglove/ws-protocol`).
const LEGACY: &str = "foxglove.websocket.v1";

/// One WebSocket connection as Foxglove opens it, offering `protocol`;
/// the server must answer with that name.
fn handshake(port: u16, protocol: &str) -> Result<WebSocket<TcpStream>, String> {
    let stream = TcpStream::connect(("127.0.0.1", port)).map_err(|e| e.to_string())?;
    stream
        .set_read_timeout(Some(Duration::from_secs(30)))
        .map_err(|e| e.to_string())?;
    let mut req = format!("ws://127.0.0.1:{port}")
        .into_client_request()
        .unwrap();
    req.headers_mut()
        .insert("Sec-WebSocket-Protocol", protocol.parse().unwrap());
    let (ws, answer) = tungstenite::client::client(req, stream).map_err(|e| match e {
        tungstenite::HandshakeError::Failure(tungstenite::Error::Http(r)) => format!(
            "{}: {}",
            r.status(),
            String::from_utf8_lossy(r.body().as_deref().unwrap_or_default())
        ),
        e => e.to_string(),
    })?;
    let chosen = answer.headers().get("Sec-WebSocket-Protocol");
    assert_eq!(chosen.and_then(|v| v.to_str().ok()), Some(protocol));
    Ok(ws)
}

/// A channel as the server advertised it.
#[derive(Debug, Clone)]
struct Advertised {
    topic: String,
    schema_name: String,
    schema: String,
}

struct Viewer {
    ws: WebSocket<TcpStream>,
    channels: HashMap<u64, Advertised>,
    /// Subscription id → channel id.
    subs: HashMap<u32, u64>,
}

impl Viewer {
    /// Connects as soon as the logger listens (watchdog: 60 s, or the
    /// launcher ending first).
    fn connect(port: u16, launcher: &mut Child, protocol: &str) -> Viewer {
        // Retried until the logger's server answers: the launcher checks the
        // port by listening on it a moment first, and a connection that
        // lands then is reset.
        let start = Instant::now();
        let ws = loop {
            assert!(
                launcher.try_wait().unwrap().is_none(),
                "the run ended before its live view listened"
            );
            assert!(
                start.elapsed() < Duration::from_secs(60),
                "nobody listens on {port}"
            );
            if let Ok(ws) = handshake(port, protocol) {
                break ws;
            }
            std::thread::sleep(Duration::from_millis(2));
        };
        let mut v = Viewer {
            ws,
            channels: HashMap::new(),
            subs: HashMap::new(),
        };
        while v.channels.len() < logger::channels().len() {
            let m = v.ws.read().unwrap();
            v.on_control(&m);
        }
        v
    }

    fn on_control(&mut self, m: &Message) {
        let Message::Text(text) = m else { return };
        let v: Value = serde_json::from_str(text).unwrap();
        if v["op"] != "advertise" {
            return;
        }
        for c in v["channels"].as_array().unwrap() {
            assert_eq!(c["encoding"], "cdr", "{c}");
            assert_eq!(c["schemaEncoding"], "ros2msg", "{c}");
            let schema = c["schema"].as_str().unwrap().to_string();
            self.channels.insert(
                c["id"].as_u64().unwrap(),
                Advertised {
                    topic: c["topic"].as_str().unwrap().into(),
                    schema_name: c["schemaName"].as_str().unwrap().into(),
                    schema,
                },
            );
        }
    }

    fn subscribe(&mut self, topics: &[&str]) {
        let mut subs = Vec::new();
        for (id, c) in &self.channels {
            if topics.is_empty() || topics.contains(&c.topic.as_str()) {
                let sub = self.subs.len() as u32 + 1;
                self.subs.insert(sub, *id);
                subs.push(json!({"id": sub, "channelId": id}));
            }
        }
        let msg = json!({"op": "subscribe", "subscriptions": subs}).to_string();
        self.ws.send(Message::text(msg)).unwrap();
    }

    /// Reads until the server closes: (topic, log time, CDR) in order.
    fn read_to_end(&mut self) -> Vec<(String, u64, Vec<u8>)> {
        let mut out = Vec::new();
        loop {
            let m = match self.ws.read() {
                Ok(m) => m,
                // The end of the run: a close frame, or (a server that could
                // not close in time) the logger process ending.
                Err(
                    tungstenite::Error::ConnectionClosed
                    | tungstenite::Error::AlreadyClosed
                    | tungstenite::Error::Protocol(
                        tungstenite::error::ProtocolError::ResetWithoutClosingHandshake,
                    ),
                ) => break,
                Err(tungstenite::Error::Io(e)) if e.kind() != std::io::ErrorKind::WouldBlock => {
                    break;
                }
                Err(e) => panic!("live view: {e}"),
            };
            let Message::Binary(b) = &m else {
                self.on_control(&m);
                continue;
            };
            // Opcode 1: message data (subscription, log time, payload).
            if b[0] != 1 {
                continue;
            }
            let sub = u32::from_le_bytes(b[1..5].try_into().unwrap());
            let t = u64::from_le_bytes(b[5..13].try_into().unwrap());
            let topic = self.channels[&self.subs[&sub]].topic.clone();
            out.push((topic, t, b[13..].to_vec()));
        }
        out
    }
}

/// The channels of the run's log: topic → (schema name, schema).
fn log_channels(log: &Path) -> BTreeMap<String, (String, String)> {
    let buf = std::fs::read(log).unwrap();
    let summary = mcap::Summary::read(&buf).unwrap().unwrap();
    summary
        .channels
        .values()
        .map(|c| {
            let s = c.schema.as_ref().unwrap();
            let schema = String::from_utf8(s.data.to_vec()).unwrap();
            (c.topic.clone(), (s.name.clone(), schema))
        })
        .collect()
}

fn live_run(port: u16, mode: &str, extra: &[&str], dir: &Path) -> Child {
    testbed()
        .args(["run", "--mode", mode, "--json", "--live"])
        .arg(format!("127.0.0.1:{port}"))
        .args(extra)
        .arg("--runs-dir")
        .arg(dir)
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap()
}

/// A lockstep run seen live: the joint states and the arm's frames arrive
/// in order, every k-th sample, CDR that decodes; the live channels are
/// the log's, with the same schemas; the log counts the client.
#[test]
fn a_lockstep_run_streams_live_what_its_log_keeps() {
    let dir = tempfile::tempdir().unwrap();
    let port = free_port();
    let mut run = live_run(port, "lockstep", &["--duration", "60"], dir.path());
    let mut viewer = Viewer::connect(port, &mut run, SDK);
    viewer.subscribe(&["/joint_state", "/tf"]);
    let got = viewer.read_to_end();
    let (status, out, err) = ended(&mut run, 300);
    assert!(status.success(), "{err}");
    let report = parse_json_str(&out);

    let mut last: HashMap<&str, u64> = HashMap::new();
    let mut counts: BTreeMap<&str, u64> = BTreeMap::new();
    for (topic, t, v) in &got {
        if let Err(e) = logger::check_message(logger::Encoding::Cdr, v) {
            panic!("{topic} at {t}: {e}");
        }
        if let Some(prev) = last.insert(topic, *t) {
            assert!(*t > prev, "{topic}: {t} after {prev}");
        }
        // 50 Hz of a 1 kHz run: every 20th sample, the same ones each run.
        assert_eq!(t % 20_000_000, 0, "{topic} at {t}");
        if topic == "/joint_state" {
            use logger::Decode;
            let s = wire::JointState::decode_as(logger::Encoding::Cdr, v).unwrap();
            assert_eq!(s.header.t_ns, *t);
        }
        *counts.entry(topic).or_default() += 1;
    }
    assert!(
        counts.get("/joint_state").copied().unwrap_or(0) >= 10,
        "{counts:?}"
    );
    assert!(counts.get("/tf").copied().unwrap_or(0) >= 10, "{counts:?}");

    // The same channels live and in the log, with the same schemas.
    let log = Path::new(report["log"].as_str().unwrap());
    let live: BTreeMap<String, (String, String)> = viewer
        .channels
        .values()
        .map(|c| (c.topic.clone(), (c.schema_name.clone(), c.schema.clone())))
        .collect();
    assert_eq!(live, log_channels(log));
    let stats = logger::read_log(log, None).unwrap().stats.unwrap();
    assert_eq!(stats["live.clients"], "1", "{stats:?}");
    assert_eq!(stats["live.client1.subscribed_at_end"], "2", "{stats:?}");
    let handed: u64 = stats["live.client1.messages"].parse().unwrap();
    assert!(handed >= got.len() as u64, "{handed} < {}", got.len());
}

/// Both subprotocol names are served, a viewer past `--live-clients` is
/// refused with the reason, and the log counts both.
#[test]
fn both_subprotocols_are_served_and_a_viewer_past_the_limit_is_refused() {
    let dir = tempfile::tempdir().unwrap();
    let port = free_port();
    let extra = ["--duration", "60", "--live-clients", "2"];
    let mut run = live_run(port, "lockstep", &extra, dir.path());
    let mut legacy = Viewer::connect(port, &mut run, LEGACY);
    let mut sdk = Viewer::connect(port, &mut run, SDK);
    let refused = handshake(port, SDK).expect_err("a third viewer was let in");
    assert!(refused.contains("503"), "{refused}");
    assert!(refused.contains("at most 2 clients"), "{refused}");
    legacy.subscribe(&["/joint_state"]);
    sdk.subscribe(&["/joint_state"]);
    let got_legacy = legacy.read_to_end();
    let got_sdk = sdk.read_to_end();
    let (status, out, err) = ended(&mut run, 300);
    assert!(status.success(), "{err}");
    assert!(got_legacy.len() >= 10, "{}", got_legacy.len());
    assert!(!got_sdk.is_empty());
    let report = parse_json_str(&out);
    let log = Path::new(report["log"].as_str().unwrap());
    let stats = logger::read_log(log, None).unwrap().stats.unwrap();
    assert_eq!(stats["live.clients"], "2", "{stats:?}");
    assert_eq!(stats["live.refused_clients"], "1", "{stats:?}");
    assert_eq!(stats["live.max_clients"], "2", "{stats:?}");
}

fn parse_json_str(out: &str) -> Value {
    serde_json::from_str(out).unwrap_or_else(|e| panic!("{e}: {out}"))
}

/// Thread names of process `pid`.
fn threads(pid: u32) -> Vec<String> {
    std::fs::read_dir(format!("/proc/{pid}/task"))
        .map(|d| {
            d.flatten()
                .filter_map(|t| std::fs::read_to_string(t.path().join("comm")).ok())
                .map(|s| s.trim().to_string())
                .collect()
        })
        .unwrap_or_default()
}

/// A real-time run with a viewer that subscribes to everything at the
/// highest rate and never reads misses no more deadlines than the same run
/// without `--live` (allowing for this shared machine's noise), and a run
/// without `--live` has no tokio thread in its logger.
#[test]
fn a_realtime_run_with_a_viewer_that_never_reads_keeps_its_deadlines() {
    let dir = tempfile::tempdir().unwrap();
    let mut plain = testbed()
        .args(["run", "--duration", "3", "--json", "--runs-dir"])
        .arg(dir.path())
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    let nodes = wait_for_nodes(plain.id());
    let logger = nodes.iter().find(|n| n.0 == "logger").unwrap().1;
    let names = threads(logger);
    assert!(!names.iter().any(|n| n.contains("tokio")), "{names:?}");
    let (status, out, err) = ended(&mut plain, 120);
    assert!(matches!(status.code(), Some(0 | 3)), "{err}");
    let base = parse_json_str(&out)["timing"]["deadline_misses"]
        .as_u64()
        .unwrap();

    let port = free_port();
    let extra = ["--duration", "3", "--live-rate", "1000"];
    let mut run = live_run(port, "realtime", &extra, dir.path());
    let mut viewer = Viewer::connect(port, &mut run, SDK);
    viewer.subscribe(&[]);
    let nodes = wait_for_nodes(run.id());
    let logger = nodes.iter().find(|n| n.0 == "logger").unwrap().1;
    let names = threads(logger);
    assert!(names.iter().any(|n| n.contains("tokio")), "{names:?}");
    // From here on the viewer reads nothing until the run is over.
    let (status, out, err) = ended(&mut run, 120);
    // Clean or degraded (a loaded machine): the misses are judged below.
    assert!(matches!(status.code(), Some(0 | 3)), "{err}");
    let report = parse_json_str(&out);
    let live = report["timing"]["deadline_misses"].as_u64().unwrap();
    let steps = report["steps"].as_u64().unwrap();
    assert!(
        live <= 2 * base + steps / 100,
        "{live} misses with a stuck viewer, {base} without"
    );
    let stats = logger::read_log(Path::new(report["log"].as_str().unwrap()), None)
        .unwrap()
        .stats
        .unwrap();
    assert_eq!(stats["live.clients"], "1", "{stats:?}");
    drop(viewer);
}

/// A taken port is refused, named, before any node starts or any file is
/// written.
#[test]
fn a_taken_live_port_fails_before_anything_starts() {
    let dir = tempfile::tempdir().unwrap();
    let taken = TcpListener::bind("127.0.0.1:0").unwrap();
    let addr = taken.local_addr().unwrap();
    let err = fails(
        testbed()
            .args(["run", "--mode", "lockstep", "--live"])
            .arg(addr.to_string())
            .arg("--runs-dir")
            .arg(dir.path()),
    );
    assert!(err.contains(&format!("--live {addr}")), "{err}");
    assert!(err.contains("in use"), "{err}");
    assert_eq!(std::fs::read_dir(dir.path()).unwrap().count(), 0);
    // And a bad value is refused by the parser.
    let err = fails(testbed().args(["run", "--live", "nowhere"]));
    assert!(err.contains("ADDR:PORT"), "{err}");
}

/// The ports process `pid` listens on at 127.0.0.1 (from its
/// `/proc/<pid>/net/tcp` rows whose sockets it holds).
fn loopback_listen_ports(pid: u32) -> Vec<u16> {
    let inodes: Vec<String> = std::fs::read_dir(format!("/proc/{pid}/fd"))
        .map(|d| {
            d.flatten()
                .filter_map(|e| std::fs::read_link(e.path()).ok())
                .filter_map(|t| {
                    let t = t.to_string_lossy().to_string();
                    Some(t.strip_prefix("socket:[")?.strip_suffix(']')?.to_string())
                })
                .collect()
        })
        .unwrap_or_default();
    let table = std::fs::read_to_string(format!("/proc/{pid}/net/tcp")).unwrap_or_default();
    table
        .lines()
        .skip(1)
        .filter_map(|l| {
            let f: Vec<&str> = l.split_whitespace().collect();
            let (local, state, inode) = (f.get(1)?, f.get(3)?, f.get(9)?);
            let (ip, port) = local.split_once(':')?;
            (ip == "0100007F" && *state == "0A" && inodes.iter().any(|i| i == inode))
                .then(|| u16::from_str_radix(port, 16).ok())?
        })
        .collect()
}

/// #39 row 8: the client limit holds on every port: a viewer that goes to
/// the server's loopback port past the relay is cut, and the log counts it.
#[test]
fn the_limit_holds_on_the_servers_own_port() {
    let dir = tempfile::tempdir().unwrap();
    let port = free_port();
    let extra = [
        "--duration",
        "30",
        "--live-clients",
        "1",
        "--no-realtime-setup",
    ];
    let mut run = live_run(port, "realtime", &extra, dir.path());
    let _viewer = Viewer::connect(port, &mut run, SDK);
    let logger = wait_for_nodes(run.id())
        .into_iter()
        .find(|n| n.0 == "logger")
        .unwrap()
        .1;
    // The logger opens its inner server after the node is up: poll for
    // it, with a watchdog (a loaded machine takes longer).
    let deadline = Instant::now() + Duration::from_secs(30);
    let inner = loop {
        if let Some(p) = loopback_listen_ports(logger)
            .into_iter()
            .find(|p| *p != port)
        {
            break p;
        }
        assert!(
            Instant::now() < deadline,
            "the server's loopback port never opened"
        );
        std::thread::sleep(Duration::from_millis(20));
    };
    let mut sneaky = TcpStream::connect(("127.0.0.1", inner)).unwrap();
    // Watchdog: a cut connection ends the read long before this.
    sneaky
        .set_read_timeout(Some(Duration::from_secs(30)))
        .unwrap();
    std::io::Write::write_all(
        &mut sneaky,
        format!(
            "GET / HTTP/1.1\r\nHost: x\r\nUpgrade: websocket\r\nConnection: Upgrade\r\n\
             Sec-WebSocket-Key: dGhlIHNhbXBsZSBub25jZQ==\r\nSec-WebSocket-Version: 13\r\n\
             Sec-WebSocket-Protocol: {SDK}\r\n\r\n"
        )
        .as_bytes(),
    )
    .unwrap();
    let started = Instant::now();
    let mut buf = [0u8; 4096];
    loop {
        match std::io::Read::read(&mut sneaky, &mut buf) {
            Ok(0) | Err(_) => break,
            Ok(_) => assert!(
                started.elapsed() < Duration::from_secs(25),
                "the connection past the relay was not cut"
            ),
        }
    }
    assert!(
        started.elapsed() < Duration::from_secs(25),
        "the connection past the relay was not cut"
    );
    let _ = nix::sys::signal::kill(
        nix::unistd::Pid::from_raw(run.id() as i32),
        nix::sys::signal::Signal::SIGINT,
    );
    let (_, _, err) = ended(&mut run, 120);
    let log = std::fs::read_dir(dir.path())
        .unwrap()
        .flatten()
        .map(|e| e.path().join("run.mcap"))
        .find(|p| p.is_file())
        .unwrap_or_else(|| panic!("no log: {err}"));
    let stats = logger::read_log(&log, None).unwrap().stats.unwrap();
    assert_ne!(stats["live.bypass_cut"], "0", "{stats:?}");
}
