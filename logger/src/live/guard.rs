//! The inner server's port is on loopback, where any local process can
//! reach it past the relay's client limit. The guard closes every
//! connection the server accepted that the relay did not make: it lists
//! this process's TCP sockets (`/proc/self/fd`, `/proc/self/net/tcp`),
//! takes those on the server's port, and shuts down each whose peer is not
//! one of the relay's own connections, once it has been seen so on two
//! looks in a row (a relay connection is registered a moment after it is
//! made).

use std::collections::HashSet;
use std::sync::Arc;
use std::sync::atomic::Ordering;
use std::time::Duration;

use super::shared::Shared;

/// How often the guard looks.
const LOOK_EVERY: Duration = Duration::from_millis(250);

/// Runs until the relay stops.
pub(super) fn guard(inner_port: u16, shared: &Arc<Shared>) {
    let mut suspects: HashSet<u64> = HashSet::new();
    while !shared.stop.load(Ordering::SeqCst) {
        std::thread::sleep(LOOK_EVERY);
        let relayed = shared.relayed_ports();
        let mut now = HashSet::new();
        for (inode, fd, peer) in accepted_on(inner_port) {
            if relayed.contains(&peer) {
                continue;
            }
            if suspects.contains(&inode) {
                // Counted before the cut: a client that sees its connection
                // end and stops the run finds the cut in the run's stats
                // (counted after, a loaded machine lost it once).
                shared.bypassed.fetch_add(1, Ordering::SeqCst);
                let _ = nix::sys::socket::shutdown(fd, nix::sys::socket::Shutdown::Both);
            } else {
                now.insert(inode);
            }
        }
        suspects = now;
    }
}

/// This process's established TCP connections whose local port is
/// `port`: (socket inode, fd, peer port).
fn accepted_on(port: u16) -> Vec<(u64, i32, u16)> {
    let mine = socket_fds();
    ["/proc/self/net/tcp", "/proc/self/net/tcp6"]
        .iter()
        .filter_map(|f| std::fs::read_to_string(f).ok())
        .flat_map(|text| {
            text.lines()
                .skip(1)
                .filter_map(parse_row)
                .collect::<Vec<_>>()
        })
        .filter(|r| r.local_port == port && r.established)
        .filter_map(|r| {
            let fd = mine.iter().find(|(inode, _)| *inode == r.inode)?.1;
            Some((r.inode, fd, r.peer_port))
        })
        .collect()
}

/// (socket inode, fd) of every socket this process holds.
fn socket_fds() -> Vec<(u64, i32)> {
    let Ok(entries) = std::fs::read_dir("/proc/self/fd") else {
        return Vec::new();
    };
    entries
        .flatten()
        .filter_map(|e| {
            let fd: i32 = e.file_name().to_str()?.parse().ok()?;
            let target = std::fs::read_link(e.path()).ok()?;
            let inode = target
                .to_str()?
                .strip_prefix("socket:[")?
                .strip_suffix(']')?
                .parse()
                .ok()?;
            Some((inode, fd))
        })
        .collect()
}

/// One row of `/proc/net/tcp`.
#[derive(Debug, PartialEq)]
struct Row {
    local_port: u16,
    peer_port: u16,
    established: bool,
    inode: u64,
}

/// `sl local rem st tx:rx tr:when retrnsmt uid timeout inode …`, with
/// addresses as `HEXIP:HEXPORT`.
fn parse_row(line: &str) -> Option<Row> {
    let f: Vec<&str> = line.split_whitespace().collect();
    let port = |a: &str| u16::from_str_radix(a.rsplit(':').next()?, 16).ok();
    Some(Row {
        local_port: port(f.get(1)?)?,
        peer_port: port(f.get(2)?)?,
        established: *f.get(3)? == "01",
        inode: f.get(9)?.parse().ok()?,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn rows_of_proc_net_tcp_read() {
        let line = "   3: 0100007F:A1B2 0100007F:C3D4 01 00000000:00000000 00:00000000 00000000     0        0 987654 1 0000000000000000 20 4 30 10 -1";
        assert_eq!(
            parse_row(line),
            Some(Row {
                local_port: 0xA1B2,
                peer_port: 0xC3D4,
                established: true,
                inode: 987654
            })
        );
        assert_eq!(parse_row("  sl  local_address"), None);
    }

    /// The guard finds a connection accepted in this process by its port.
    #[test]
    fn a_connection_accepted_here_is_found_with_its_peer() {
        let listener = std::net::TcpListener::bind("127.0.0.1:0").unwrap();
        let port = listener.local_addr().unwrap().port();
        let client = std::net::TcpStream::connect(("127.0.0.1", port)).unwrap();
        let (_server_side, _) = listener.accept().unwrap();
        let found = accepted_on(port);
        let peer = client.local_addr().unwrap().port();
        assert!(found.iter().any(|(_, _, p)| *p == peer), "{found:?}");
    }
}
