//! The path recorder against the definition: the pixel is every radiance
//! found times the throughput when it was found, and the radiance arriving
//! along a segment is everything found after it, carried back through the
//! throughput factors between (recorded or specular).

mod common;

use common::{DirectionsAt, Rand};
use glam::Vec3;
use guiding::luminance;
use guiding::math::{Aabb, Accumulation};
use guiding::sd_tree::{SdTree, SdTreeConfig};
use guiding::{PathRecorder, ShadingContext, mis};

/// One event of a random path.
#[derive(Clone, Copy, Debug)]
enum Event {
    Found(Vec3),
    Segment(Vec3),
    Specular(Vec3),
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
    let mut recorder = PathRecorder::new();
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
                    recorder.push_segment(None, Vec3::Z, 1.0, 0.5, 0.5, w);
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
        recorder.finish();
        let got = recorder.segments();
        assert_eq!(got.len(), segments as usize);
        for (k, s) in got.iter().enumerate() {
            assert!(
                close(s.incident, incident(k as u32)),
                "{events:?} segment {k}"
            );
        }
    }
}

/// A path whose throughput zeroes the red channel after the first bounce
/// still delivers the green light it found later to the first vertex
/// (dividing by the throughput, as hand-written bookkeeping often does,
/// would lose it where the throughput is zero).
#[test]
fn a_zero_channel_loses_nothing_else() {
    let mut r = PathRecorder::new();
    r.push_segment(None, Vec3::Z, 1.0, 1.0, 0.0, Vec3::new(0.0, 1.0, 1.0));
    r.push_segment(None, Vec3::Z, 1.0, 1.0, 0.0, Vec3::new(1.0, 0.5, 1.0));
    r.add_radiance(Vec3::new(4.0, 2.0, 0.0));
    r.add_radiance(Vec3::NAN); // ignored
    r.finish();
    let got = r.segments();
    assert_eq!(got[1].incident, Vec3::new(4.0, 2.0, 0.0));
    assert_eq!(got[0].incident, Vec3::new(4.0, 1.0, 0.0));
    assert_eq!(r.estimate(), Vec3::new(0.0, 1.0, 0.0));
}

/// Into an SD-tree: each segment's vertex gets exactly the two records a
/// renderer would make by hand (PPG's radiance record of the luminance of
/// the incident radiance with the segment's pdf, the fraction record of
/// its two pdfs and the luminance of weight times incident radiance), so
/// the learned state is bit for bit the same; the control, a recorder that
/// delivered the throughput-weighted radiance instead, learns otherwise.
#[test]
fn records_into_an_sd_tree() {
    let scene = Aabb::new(Vec3::splat(-1.0), Vec3::splat(1.0));
    let config = SdTreeConfig {
        learn_bsdf_fraction: true,
        accumulation: Accumulation::Deterministic,
        ..SdTreeConfig::default()
    };
    let (mut by_recorder, mut by_hand, mut control) = (
        SdTree::new(scene, config).unwrap(),
        SdTree::new(scene, config).unwrap(),
        SdTree::new(scene, config).unwrap(),
    );
    let mut r = PathRecorder::new();
    let mut rng = Rand::new(3);
    for _ in 0..2000 {
        let (p, q) = (rng.point(0.9), rng.point(0.9));
        let (d0, d1) = (rng.dir(), rng.dir());
        let (w0, w1) = (colour(&mut rng), colour(&mut rng));
        let (e0, e1) = (colour(&mut rng), colour(&mut rng));
        r.clear();
        r.push_segment(
            by_recorder.vertex(&ShadingContext::at(p)),
            d0,
            0.25,
            0.3,
            0.1,
            w0,
        );
        r.add_radiance(e0);
        r.push_segment(
            by_recorder.vertex(&ShadingContext::at(q)),
            d1,
            0.5,
            0.2,
            0.4,
            w1,
        );
        r.add_radiance(e1);
        r.finish();
        // By hand: L_1 = e1, L_0 = e0 + w1 e1.
        let (l0, l1) = (e0 + w1 * e1, e1);
        for (t, weigh) in [(&by_hand, false), (&control, true)] {
            let v = t.direction_at(p);
            let l = if weigh { w0 * l0 } else { l0 };
            v.record_radiance(d0, luminance(l), 0.25);
            v.record_fraction(0.3, 0.1, luminance(w0 * l0));
            let v = t.direction_at(q);
            let l = if weigh { w1 * l1 } else { l1 };
            v.record_radiance(d1, luminance(l), 0.5);
            v.record_fraction(0.2, 0.4, luminance(w1 * l1));
        }
    }
    assert_eq!(by_recorder.dropped_records().total(), 0);
    for t in [&mut by_recorder, &mut by_hand, &mut control] {
        t.refine();
    }
    assert_eq!(by_recorder.to_bytes(), by_hand.to_bytes());
    assert_ne!(by_recorder.to_bytes(), control.to_bytes());
    // MIS weights of the two techniques sum to one.
    let (a, b) = (0.3, 1.7);
    assert!((mis::power_heuristic(a, b) + mis::power_heuristic(b, a) - 1.0).abs() < 1e-6);
}
