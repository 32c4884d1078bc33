use core::fmt;

/// Why a light tree could not be built or refitted. Every variant about
/// one emitter names it so a renderer can report it.
#[derive(Clone, Copy, Debug, PartialEq)]
#[non_exhaustive]
pub enum BuildError {
    /// An emitter's bounds are empty, NaN or infinite.
    InvalidBounds {
        /// The emitter's index.
        emitter: usize,
    },
    /// An emitter's power is NaN, infinite or negative.
    InvalidPower {
        /// The emitter's index.
        emitter: usize,
        /// The power it reported.
        power: f32,
    },
    /// An emitter's weight ([`Emitters::weight`](crate::Emitters::weight))
    /// is NaN, infinite or negative.
    InvalidWeight {
        /// The emitter's index.
        emitter: usize,
        /// The weight it reported.
        weight: f32,
    },
    /// An emitter's area is NaN, infinite or negative.
    InvalidArea {
        /// The emitter's index.
        emitter: usize,
        /// The area it reported.
        area: f32,
    },
    /// An emitter's cone has a non-finite axis or angle.
    InvalidCone {
        /// The emitter's index.
        emitter: usize,
    },
    /// More emitters than node indices can address (2^31 - 1).
    TooManyEmitters {
        /// How many were given.
        count: usize,
    },
    /// The total power (times the weights) does not fit in an `f32`.
    PowerOverflow,
    /// An instance of an [`InstancedLightTree`](super::InstancedLightTree)
    /// names no mesh, has a non-finite or singular transform, or a power
    /// scale that is not a finite number >= 0.
    InvalidInstance {
        /// The instance's index.
        instance: usize,
    },
    /// [`LightTree::refit`](super::LightTree::refit) was given another
    /// number of emitters than the tree holds.
    EmitterCount {
        /// The tree's emitters.
        tree: usize,
        /// How many were given.
        given: usize,
    },
}

impl fmt::Display for BuildError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match *self {
            Self::InvalidBounds { emitter } => {
                write!(f, "emitter {emitter} has empty or non-finite bounds")
            }
            Self::InvalidPower { emitter, power } => {
                write!(f, "emitter {emitter} has invalid power {power}")
            }
            Self::InvalidWeight { emitter, weight } => {
                write!(f, "emitter {emitter} has invalid weight {weight}")
            }
            Self::InvalidArea { emitter, area } => {
                write!(f, "emitter {emitter} has invalid area {area}")
            }
            Self::InvalidCone { emitter } => {
                write!(f, "emitter {emitter} has a non-finite emission cone")
            }
            Self::TooManyEmitters { count } => {
                write!(
                    f,
                    "{count} emitters exceed the 2^31 - 1 a light tree can index"
                )
            }
            Self::PowerOverflow => f.write_str("the total emitted power overflows f32"),
            Self::InvalidInstance { instance } => write!(
                f,
                "instance {instance} names no mesh, or its transform or power scale is invalid"
            ),
            Self::EmitterCount { tree, given } => write!(
                f,
                "a refit needs the tree's {tree} emitters, {given} were given"
            ),
        }
    }
}

impl core::error::Error for BuildError {}
