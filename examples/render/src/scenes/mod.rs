//! The scenes, generated in code: analogues of the paper's, plus a smoke
//! test box.

mod city;
mod cornell;
mod few_lights;
mod occlusion;
mod pool;
mod ring;
pub mod shapes;
mod torus;

use crate::scene::Scene;

/// How big to make a scene.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Size {
    /// As documented (the analogue of the paper's scene).
    Full,
    /// Fewer lights and objects, for fast tests.
    Small,
}

/// Every scene name, in the order `--scene all` renders them.
pub const NAMES: &[&str] = &[
    "ring",
    "city",
    "city-street",
    "pool",
    "torus",
    "occlusion",
    "few-lights",
    "box",
];

/// The scene a run without arguments renders: the city seen from the
/// street, where learning the light choice pays most (docs/results.md),
/// and whose reference at [`DEFAULT_SIZE`] is committed to the repository.
pub const DEFAULT: &str = "city-street";

/// The image size a run renders unless told otherwise.
pub const DEFAULT_SIZE: (u32, u32) = (256, 192);

/// Builds the scene called `name`; `None` for an unknown name. Besides
/// [`NAMES`], `city:<blocks>` is the city on a `blocks` x `blocks` grid
/// (`city` is `city:20`), whatever `size`: the light count grows as
/// `blocks^2` (`choice_cost` measures cost against it).
pub fn build(name: &str, size: Size) -> Option<Scene> {
    if let Some(blocks) = name.strip_prefix("city:") {
        return blocks.parse().ok().map(city::build_blocks);
    }
    Some(match name {
        "ring" => ring::build(size),
        "city" => city::build(size),
        "city-street" => city::build_street(size),
        "pool" => pool::build(size),
        "torus" => torus::build(size),
        "occlusion" => occlusion::build(size),
        "few-lights" => few_lights::build(size),
        "box" => cornell::build(size),
        _ => return None,
    })
}

/// A deterministic stream of uniform numbers for scene generation.
pub struct Dice(crate::rng::Sampler);

impl Dice {
    /// The stream for `seed`.
    pub fn new(seed: u64) -> Self {
        Self(crate::rng::Sampler::new(seed, u64::MAX, 0))
    }

    /// A number in `[lo, hi)`.
    pub fn range(&mut self, lo: f32, hi: f32) -> f32 {
        lo + (hi - lo) * self.0.next()
    }

    /// True with probability `p`.
    pub fn chance(&mut self, p: f32) -> bool {
        self.0.next() < p
    }
}
