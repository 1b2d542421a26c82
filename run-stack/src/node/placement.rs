//! Where and how a node runs: which CPUs, which scheduling policy, whether
//! its memory is locked. The launcher decides (see [`for_node`]); each node
//! applies its own placement at start-up, and says clearly when the system
//! refuses part of it (the run goes on, with worse timing).

use nix::sched::{CpuSet, sched_setaffinity};
use nix::sys::mman::{MlockAllFlags, mlockall};
use nix::unistd::Pid;
use thread_priority::{
    RealtimeThreadSchedulePolicy, ThreadPriority, ThreadPriorityValue, ThreadSchedulePolicy,
    set_thread_priority_and_policy, thread_native_id,
};
use wire::NodeKind;

use crate::mode::Mode;

/// A node's placement, as given on its command line.
#[derive(Debug, Clone, Default, PartialEq, Eq, clap::Args)]
pub struct Placement {
    /// Pin the node to these CPUs (comma-separated indices).
    #[arg(long, value_delimiter = ',', value_name = "CPU,…")]
    pub cpus: Vec<usize>,
    /// Run under SCHED_FIFO at this priority (1–99).
    #[arg(long, value_name = "PRIORITY", value_parser = clap::value_parser!(u8).range(1..=99))]
    pub fifo: Option<u8>,
    /// Lock the node's memory (mlockall), so no page fault stalls the loop.
    #[arg(long)]
    pub lock_memory: bool,
}

impl Placement {
    /// The command-line form, for the launcher.
    pub fn to_args(&self) -> Vec<String> {
        let mut args = Vec::new();
        if !self.cpus.is_empty() {
            args.push("--cpus".to_string());
            args.push(
                self.cpus
                    .iter()
                    .map(usize::to_string)
                    .collect::<Vec<_>>()
                    .join(","),
            );
        }
        if let Some(p) = self.fifo {
            args.push("--fifo".to_string());
            args.push(p.to_string());
        }
        if self.lock_memory {
            args.push("--lock-memory".to_string());
        }
        args
    }

    /// Applies the placement to this process; returns what the system
    /// refused, one sentence each.
    pub fn apply(&self) -> Vec<String> {
        let mut refused = Vec::new();
        if !self.cpus.is_empty() {
            let mut set = CpuSet::new();
            let pinned = self
                .cpus
                .iter()
                .try_for_each(|&c| set.set(c))
                .and_then(|()| sched_setaffinity(Pid::from_raw(0), &set));
            if let Err(e) = pinned {
                refused.push(format!("cannot pin to CPUs {:?} ({e})", self.cpus));
            }
        }
        if let Some(p) = self.fifo {
            let priority = ThreadPriorityValue::try_from(p).map(ThreadPriority::Crossplatform);
            let set = priority.map_err(|e| e.to_string()).and_then(|priority| {
                set_thread_priority_and_policy(
                    thread_native_id(),
                    priority,
                    ThreadSchedulePolicy::Realtime(RealtimeThreadSchedulePolicy::Fifo),
                )
                .map_err(|e| match e {
                    thread_priority::Error::OS(code) => {
                        nix::errno::Errno::from_raw(code).to_string()
                    }
                    other => format!("{other:?}"),
                })
            });
            if let Err(e) = set {
                refused.push(format!(
                    "SCHED_FIFO priority {p} refused ({e}); the loop runs under the normal \
                     scheduler and its jitter follows the machine's load. Run as root, or grant \
                     CAP_SYS_NICE or an rtprio limit (ulimit -r), to allow it"
                ));
            }
        }
        if self.lock_memory
            && let Err(e) = mlockall(MlockAllFlags::MCL_CURRENT | MlockAllFlags::MCL_FUTURE)
        {
            refused.push(format!(
                "cannot lock memory ({e}); page faults may stall the loop. Raise the \
                 memlock limit (ulimit -l) or grant CAP_IPC_LOCK"
            ));
        }
        refused
    }
}

/// Keeps the calling thread off the loop's CPU (the last one) until
/// dropped, then restores its CPU set: the launcher wakes every 10 ms to
/// supervise and should not preempt the plant or the controller.
pub struct OffLoopCpu(Option<CpuSet>);

impl OffLoopCpu {
    /// Moves the calling thread to every CPU but the last (when there are two or more).
    pub fn enter(cpus: usize) -> Self {
        if cpus < 2 {
            return Self(None);
        }
        let Ok(before) = nix::sched::sched_getaffinity(Pid::from_raw(0)) else {
            return Self(None);
        };
        let mut set = CpuSet::new();
        if (0..cpus - 1).try_for_each(|c| set.set(c)).is_err()
            || sched_setaffinity(Pid::from_raw(0), &set).is_err()
        {
            return Self(None);
        }
        Self(Some(before))
    }
}

impl Drop for OffLoopCpu {
    fn drop(&mut self) {
        if let Some(before) = &self.0 {
            let _ = sched_setaffinity(Pid::from_raw(0), before);
        }
    }
}

/// CPUs this process may use (1 when unknown).
pub fn cpu_count() -> usize {
    std::thread::available_parallelism().map_or(1, usize::from)
}

/// The launcher's placement of `kind` on a machine with `cpus` CPUs.
///
/// The plant and the controller wake each other every period: on one CPU
/// that round trip costs about 14 µs, across CPUs 50–70 µs (NOTES.md), so
/// they share the last CPU and the trajectory and the logger get the others.
/// In real time the plant and the controller also run under SCHED_FIFO
/// with locked memory, the controller one level above the plant: a state
/// the plant publishes then wakes the controller at once, even when the
/// plant is catching up after the host stalled it, so the answer is there
/// by the next tick (with the plant higher, every catch-up tick was a miss).
/// The trajectory (70) and the logger (60) run under SCHED_FIFO too, below
/// the loop, on the other CPUs: a busy machine then delays neither the
/// reference (published a horizon ahead) nor the log (whose buffers hold
/// two seconds), where under the normal scheduler a CPU hog starved the
/// trajectory for 420 ms and the logger dropped rows. In lockstep the
/// pair keeps its CPU busy, and a FIFO task that never sleeps would only be
/// throttled, so lockstep pins without raising priority.
pub fn for_node(kind: NodeKind, mode: Mode, cpus: usize) -> Placement {
    let loop_node = matches!(kind, NodeKind::Plant | NodeKind::Controller);
    let cpu_list = if cpus < 2 {
        Vec::new()
    } else if loop_node {
        vec![cpus - 1]
    } else {
        (0..cpus - 1).collect()
    };
    let fifo = match (mode, kind) {
        (Mode::Lockstep, _) => None,
        (Mode::Realtime, NodeKind::Controller) => Some(80),
        (Mode::Realtime, NodeKind::Plant) => Some(79),
        (Mode::Realtime, NodeKind::Trajectory) => Some(70),
        (Mode::Realtime, NodeKind::Logger) => Some(60),
    };
    Placement {
        cpus: cpu_list,
        fifo,
        // The logger's buffers (compression, live view) are large and
        // its deadline is seconds away: not locked.
        lock_memory: mode == Mode::Realtime && kind != NodeKind::Logger,
    }
}

/// A user's controller (`run --controller-cmd`) runs just below the plant
/// on the loop's CPU: a controller slower than the testbed's must not hold
/// the clock back; its lateness then shows as its own deadline misses.
pub fn below_the_plant(p: Placement) -> Placement {
    let plant = for_node(NodeKind::Plant, Mode::Realtime, 2).fifo;
    Placement {
        fifo: p.fifo.and(plant.map(|f| f - 1)),
        ..p
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_users_controller_runs_below_the_plant_on_the_loop_cpu() {
        let c = below_the_plant(for_node(NodeKind::Controller, Mode::Realtime, 2));
        assert_eq!((c.cpus.as_slice(), c.fifo), (&[1][..], Some(78)));
        let lockstep = below_the_plant(for_node(NodeKind::Controller, Mode::Lockstep, 2));
        assert_eq!(lockstep.fifo, None);
    }

    #[test]
    fn the_loop_shares_one_cpu_and_the_rest_get_the_others() {
        let p = for_node(NodeKind::Plant, Mode::Realtime, 2);
        assert_eq!(p.cpus, [1]);
        assert_eq!(p.fifo, Some(79));
        assert!(p.lock_memory);
        let c = for_node(NodeKind::Controller, Mode::Realtime, 4);
        assert_eq!((c.cpus.as_slice(), c.fifo), (&[3][..], Some(80)));
        let l = for_node(NodeKind::Logger, Mode::Realtime, 4);
        assert_eq!(
            l,
            Placement {
                cpus: vec![0, 1, 2],
                fifo: Some(60),
                lock_memory: false
            }
        );
        let t = for_node(NodeKind::Trajectory, Mode::Realtime, 2);
        assert_eq!((t.cpus.as_slice(), t.fifo), (&[0][..], Some(70)));
        assert_eq!(for_node(NodeKind::Logger, Mode::Lockstep, 2).fifo, None);
        let lockstep = for_node(NodeKind::Plant, Mode::Lockstep, 2);
        assert_eq!((lockstep.fifo, lockstep.lock_memory), (None, false));
        assert!(for_node(NodeKind::Plant, Mode::Realtime, 1).cpus.is_empty());
    }

    #[test]
    fn arguments_round_trip() {
        use clap::Parser;
        #[derive(Parser)]
        struct Cli {
            #[command(flatten)]
            p: Placement,
        }
        let p = for_node(NodeKind::Plant, Mode::Realtime, 4);
        let mut argv = vec!["x".to_string()];
        argv.extend(p.to_args());
        assert_eq!(Cli::parse_from(argv).p, p);
    }
}
