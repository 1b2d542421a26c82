//! Room in /dev/shm for a run's services. iceoryx2 sizes its segments with
//! `ftruncate` and touches their pages later: on a full /dev/shm the first
//! node to touch one dies of SIGBUS, which says nothing of the cause
//! (#60 item 7). So the launcher asks for the room before it starts.

/// The folder POSIX shared memory lives in on Linux.
pub const SHM_DIR: &str = "/dev/shm";

/// The room a run asks for: a two-link lockstep run's services held at
/// most 5.7 MB of /dev/shm (measured 2026-12-07 with `df` every 0.1 s);
/// messages are fixed-size, so every arm's are the same. Three times that
/// leaves room for the live view's and the logger's buffers to grow.
pub const SHM_NEEDED_BYTES: u64 = 16 << 20;

/// The bytes free in /dev/shm (None: it cannot be asked, as on a system
/// without it; the run then goes ahead).
pub fn shm_free_bytes() -> Option<u64> {
    let s = nix::sys::statvfs::statvfs(SHM_DIR).ok()?;
    Some(s.blocks_available().saturating_mul(s.fragment_size()))
}

/// Why /dev/shm cannot hold a run, if it cannot.
pub fn shm_too_small() -> Option<String> {
    let free = shm_free_bytes()?;
    (free < SHM_NEEDED_BYTES).then(|| {
        format!(
            "{SHM_DIR} has {free} bytes free; a run's shared-memory services need about \
             {SHM_NEEDED_BYTES} ({} MiB): free space there or make it larger (`mount -o remount,size=64M {SHM_DIR}`)",
            SHM_NEEDED_BYTES >> 20
        )
    })
}
