//! Which effects acted on a logged state.

/// A set of effects, as bits (the `effects` field of the wire's joint state).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct Effects(pub u32);

impl Effects {
    /// Joint friction is on.
    pub const FRICTION: u32 = 1 << 0;
    /// The payload is attached.
    pub const PAYLOAD: u32 = 1 << 1;
    /// A disturbance d(t) is configured.
    pub const DISTURBANCE: u32 = 1 << 2;
    /// Some joint's torque was clipped at its effort limit over the period.
    pub const SATURATED: u32 = 1 << 3;
    /// q or q̇ carries sensor noise.
    pub const SENSOR_NOISE: u32 = 1 << 4;
    /// q is quantised to an encoder's resolution.
    pub const QUANTISED: u32 = 1 << 5;
    /// Commands reach the motors some periods late.
    pub const DELAYED: u32 = 1 << 6;
    /// The period's command was lost on the way (the motors held the last one).
    pub const COMMAND_DROPPED: u32 = 1 << 7;
    /// No new command reached the motors this period (lost, or not there in
    /// time): the last one was held.
    pub const COMMAND_HELD: u32 = 1 << 8;
    /// The motor torque follows the command through a lag or a slew limit.
    pub const MOTOR_LAG: u32 = 1 << 9;
    /// Some transmission has gear backlash.
    pub const BACKLASH: u32 = 1 << 10;
    /// Some motor cogs (torque harmonics in its angle).
    pub const COGGING: u32 = 1 << 11;
    /// Some joint is series elastic (a spring between motor and link).
    pub const ELASTIC: u32 = 1 << 12;
    /// Some link touched an obstacle (or another link) during the period.
    pub const CONTACT: u32 = 1 << 13;

    const NAMES: [(u32, &'static str); 14] = [
        (Self::FRICTION, "friction"),
        (Self::PAYLOAD, "payload"),
        (Self::DISTURBANCE, "disturbance"),
        (Self::SATURATED, "saturated"),
        (Self::SENSOR_NOISE, "sensor_noise"),
        (Self::QUANTISED, "quantised"),
        (Self::DELAYED, "delayed"),
        (Self::COMMAND_DROPPED, "command_dropped"),
        (Self::COMMAND_HELD, "command_held"),
        (Self::MOTOR_LAG, "motor_lag"),
        (Self::BACKLASH, "backlash"),
        (Self::COGGING, "cogging"),
        (Self::ELASTIC, "elastic"),
        (Self::CONTACT, "contact"),
    ];

    /// Whether every bit of `bits` is set.
    pub fn has(self, bits: u32) -> bool {
        self.0 & bits == bits
    }

    /// The names of the set bits, in bit order.
    pub fn names(self) -> Vec<&'static str> {
        Self::NAMES
            .iter()
            .filter(|(b, _)| self.0 & b != 0)
            .map(|(_, n)| *n)
            .collect()
    }

    /// Every effect's name, in bit order (for documentation and schemas).
    pub fn all_names() -> impl Iterator<Item = &'static str> {
        Self::NAMES.iter().map(|(_, n)| *n)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn names_follow_the_bits() {
        let e = Effects(Effects::FRICTION | Effects::COMMAND_HELD);
        assert_eq!(e.names(), ["friction", "command_held"]);
        assert!(e.has(Effects::FRICTION));
        assert!(!e.has(Effects::PAYLOAD));
        assert_eq!(Effects::all_names().count(), 14);
    }
}
