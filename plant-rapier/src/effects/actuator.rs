//! The path from the controller to the motors: commands may be lost (the
//! motors then hold the last one) and arrive N periods late.

use rand::Rng;
use rand_chacha::ChaCha8Rng;

/// Zero-order hold, loss and a delay line of whole control periods.
pub(crate) struct Actuator {
    n: usize,
    /// The command the motors hold (zero before the first one).
    held: Vec<f64>,
    /// `delay` commands in flight, oldest at `head`, flattened n per entry.
    line: Vec<f64>,
    head: usize,
    delay: usize,
    drop_probability: f64,
    rng: ChaCha8Rng,
    out: Vec<f64>,
}

/// What happened to one period's command.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) struct Passage {
    /// The command was lost on the way.
    pub dropped: bool,
    /// No new command was taken (lost or absent): the last one is held.
    pub held: bool,
}

impl Actuator {
    pub(crate) fn new(n: usize, delay: u32, drop_probability: f64, rng: ChaCha8Rng) -> Self {
        let delay = delay as usize;
        Self {
            n,
            held: vec![0.0; n],
            line: vec![0.0; n * delay],
            head: 0,
            delay,
            drop_probability,
            rng,
            out: vec![0.0; n],
        }
    }

    /// Takes this period's command (None: none arrived) and returns what the
    /// motors apply over the period.
    pub(crate) fn pass(&mut self, command: Option<&[f64]>) -> Passage {
        let dropped = command.is_some()
            && self.drop_probability > 0.0
            && self.rng.random::<f64>() < self.drop_probability;
        let taken = command.filter(|_| !dropped);
        if let Some(c) = taken {
            self.held.copy_from_slice(c);
        }
        if self.delay == 0 {
            self.out.copy_from_slice(&self.held);
        } else {
            // The oldest command in flight comes out; this one goes in.
            let slot = self.head * self.n..(self.head + 1) * self.n;
            self.out.copy_from_slice(&self.line[slot.clone()]);
            self.line[slot].copy_from_slice(&self.held);
            self.head = (self.head + 1) % self.delay;
        }
        Passage {
            dropped,
            held: taken.is_none(),
        }
    }

    /// What the motors apply over the current period.
    pub(crate) fn output(&self) -> &[f64] {
        &self.out
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::effects::stream;

    #[test]
    fn a_delay_of_n_periods_shifts_commands_by_n() {
        let mut a = Actuator::new(1, 3, 0.0, stream(0, 0));
        let outs: Vec<f64> = (1..=6)
            .map(|k| {
                a.pass(Some(&[k as f64]));
                a.output()[0]
            })
            .collect();
        assert_eq!(outs, [0.0, 0.0, 0.0, 1.0, 2.0, 3.0]);
    }

    #[test]
    fn a_missing_command_holds_the_last_one() {
        let mut a = Actuator::new(2, 0, 0.0, stream(0, 0));
        a.pass(Some(&[1.0, 2.0]));
        let p = a.pass(None);
        assert_eq!(a.output(), [1.0, 2.0]);
        assert!(p.held && !p.dropped);
    }

    #[test]
    fn commands_are_lost_at_the_set_rate() {
        let mut a = Actuator::new(1, 0, 0.2, stream(7, 3));
        let lost = (0..20_000)
            .filter(|&k| a.pass(Some(&[k as f64])).dropped)
            .count();
        // Binomial(20000, 0.2): σ ≈ 57, so ±300 is over 5σ.
        assert!((lost as i64 - 4000).abs() < 300, "{lost}");
    }
}
