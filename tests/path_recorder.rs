//! The path recorder against the definition: the pixel is every radiance
//! found times the throughput when it was found, and the radiance arriving
//! along a segment is everything found after it, carried back through the
//! throughput factors between (recorded or specular).

mod common;

use common::Rand;
use glam::Vec3;
use guiding::math::Aabb;
use guiding::path_recorder::{RadianceRecords, Segment};
use guiding::sd_tree::{SdTree, SdTreeConfig};
use guiding::spatial::Jitter;
use guiding::{PathRecorder, mis};
use std::cell::RefCell;

/// One event of a random path.
#[derive(Clone, Copy, Debug)]
enum Event {
    Found(Vec3),
    Segment(Vec3),
    Specular(Vec3),
}

/// Collects what the recorder delivers.
#[derive(Default)]
struct Collect(RefCell<Vec<(u32, Vec3, f32, f32)>>);

impl RadianceRecords<u32> for Collect {
    fn record<J: Jitter + ?Sized>(
        &self,
        s: &Segment<u32>,
        radiance: f32,
        contribution: f32,
        _: &mut J,
    ) {
        self.0
            .borrow_mut()
            .push((s.cell, s.incident, radiance, contribution));
    }
}

fn colour(rng: &mut Rand) -> Vec3 {
    // Some channels exactly zero: a throughput that kills a channel must
    // not lose the others.
    let c = |rng: &mut Rand| {
        if rng.f() < 0.2 {
            0.0
        } else {
            rng.range(0.0, 2.0)
        }
    };
    Vec3::new(c(rng), c(rng), c(rng))
}

#[test]
fn matches_the_definition_on_random_paths() {
    let mut rng = Rand::new(11);
    let mut recorder = PathRecorder::<u32>::new();
    for _ in 0..500 {
        let events: Vec<Event> = (0..rng.below(12) + 1)
            .map(|_| match rng.below(3) {
                0 => Event::Found(colour(&mut rng)),
                1 => Event::Segment(colour(&mut rng)),
                _ => Event::Specular(colour(&mut rng)),
            })
            .collect();
        recorder.clear();
        let mut segments = 0u32;
        for e in &events {
            match *e {
                Event::Found(c) => recorder.add_radiance(c),
                Event::Segment(w) => {
                    recorder.push_segment(segments, Vec3::ZERO, Vec3::Z, 1.0, 0.5, 0.5, w);
                    segments += 1;
                }
                Event::Specular(w) => recorder.scatter_unrecorded(w),
            }
        }
        // The definition, by brute force over the event list.
        let mut pixel = Vec3::ZERO;
        let mut beta = Vec3::ONE;
        for e in &events {
            match *e {
                Event::Found(c) => pixel += beta * c,
                Event::Segment(w) | Event::Specular(w) => beta *= w,
            }
        }
        let incident = |k: u32| {
            // Everything found after segment k was pushed, times the
            // factors of every scattering after it.
            let (mut sum, mut seen, mut t) = (Vec3::ZERO, 0u32, Vec3::ONE);
            let mut after = false;
            for e in &events {
                match *e {
                    Event::Segment(w) => {
                        if after {
                            t *= w;
                        }
                        if seen == k {
                            after = true;
                        }
                        seen += 1;
                    }
                    Event::Specular(w) if after => t *= w,
                    Event::Found(c) if after => sum += t * c,
                    _ => {}
                }
            }
            sum
        };
        let close =
            |a: Vec3, b: Vec3| (a - b).abs().max_element() <= 1e-5 * (1.0 + b.abs().max_element());
        assert!(close(recorder.estimate(), pixel), "{events:?}");
        let sink = Collect::default();
        recorder.finish(&sink, &mut rand_pcg::Pcg32::new(1, 1));
        let got = sink.0.into_inner();
        assert_eq!(got.len(), segments as usize);
        for (k, (cell, inc, radiance, contribution)) in got.into_iter().enumerate() {
            assert_eq!(cell, k as u32);
            assert!(close(inc, incident(k as u32)), "{events:?} segment {k}");
            let w = recorder.segments()[k].weight;
            let lum = |c: Vec3| 0.2126 * c.x + 0.7152 * c.y + 0.0722 * c.z;
            assert_eq!(radiance, lum(inc));
            assert_eq!(contribution, lum(w * inc));
        }
    }
}

/// A path whose throughput zeroes the red channel after the first bounce
/// still delivers the green light it found later to the first vertex
/// (dividing by the throughput, as hand-written bookkeeping often does,
/// would lose it where the throughput is zero).
#[test]
fn a_zero_channel_loses_nothing_else() {
    let mut r = PathRecorder::<u32>::new();
    r.push_segment(
        0,
        Vec3::ZERO,
        Vec3::Z,
        1.0,
        1.0,
        0.0,
        Vec3::new(0.0, 1.0, 1.0),
    );
    r.push_segment(
        1,
        Vec3::ZERO,
        Vec3::Z,
        1.0,
        1.0,
        0.0,
        Vec3::new(1.0, 0.5, 1.0),
    );
    r.add_radiance(Vec3::new(4.0, 2.0, 0.0));
    r.add_radiance(Vec3::NAN); // ignored
    let sink = Collect::default();
    r.finish(&sink, &mut rand_pcg::Pcg32::new(1, 1));
    let got = sink.0.into_inner();
    assert_eq!(got[1].1, Vec3::new(4.0, 2.0, 0.0));
    assert_eq!(got[0].1, Vec3::new(4.0, 1.0, 0.0));
    assert_eq!(r.estimate(), Vec3::new(0.0, 1.0, 0.0));
}

/// Into an SD-tree: the records land in the cell and direction they name.
#[test]
fn records_into_an_sd_tree() {
    let scene = Aabb::new(Vec3::splat(-1.0), Vec3::splat(1.0));
    let mut tree = SdTree::new(scene, SdTreeConfig::default()).unwrap();
    let mut r = PathRecorder::new();
    let mut rng = rand_pcg::Pcg32::new(3, 7);
    for _ in 0..2000 {
        r.clear();
        r.push_segment((), Vec3::ZERO, Vec3::Y, 0.25, 0.25, 0.0, Vec3::ONE);
        r.add_radiance(Vec3::splat(1.0));
        r.finish(&tree, &mut rng);
    }
    assert_eq!(tree.dropped_splats().total(), 0);
    tree.refine();
    assert!(tree.pdf(Vec3::ZERO, Vec3::Y) > 10.0 * tree.pdf(Vec3::ZERO, -Vec3::Y));
    // MIS weights of the two techniques sum to one.
    let (a, b) = (0.3, 1.7);
    assert!((mis::power_heuristic(a, b) + mis::power_heuristic(b, a) - 1.0).abs() < 1e-6);
}
