//! `render --frames N`: an animation's frames ([`crate::animation`]), each
//! trained method rendering every frame three ways at the same budget:
//!
//! - **from scratch**: the frame's light tree built anew, the guide learned
//!   anew;
//! - **carried, tree kept**: the guide the previous frame ended with, over
//!   the first frame's light tree as it was built (the lights have moved
//!   since; the choice stays unbiased, only worse);
//! - **carried, tree refitted**: the same, over the previous frame's tree
//!   refitted to this frame's lights (`LightTree::refit`, then the guide
//!   loaded over it: a saved guide binds to the tree's shape).
//!
//! Each frame is measured against its own reference. The carried guides
//! travel between frames as saved files (`<out>/<scene>/frames/<way>/`),
//! as they would between the processes of a render farm.

use crate::cli::Args;
use crate::methods::Method;
use crate::run::{self, Budget, GuideFiles, Settings};
use crate::{animation, metrics, reference, scenes};
use guiding::LightTree;
use std::fmt::Write as _;

/// Renders `frames` frames of scene `name` with the trained `methods` three
/// ways each and returns the table (also written to
/// `<out>/<name>/frames.md`).
pub fn run(
    args: &Args,
    name: &str,
    size: scenes::Size,
    methods: &[Method],
    settings: &Settings,
    reference_method: Method,
    reference_budget: Budget,
) -> Result<String, String> {
    let base = scenes::build(name, size).ok_or_else(|| format!("unknown scene {name}"))?;
    let methods: Vec<Method> = methods.iter().copied().filter(|m| m.is_trained()).collect();
    if methods.is_empty() {
        return Err("--frames compares trained methods (pt-glt, ppg, ppg-glt)".into());
    }
    let dir = args.out.join(name).join("frames");
    let budget = match settings.budget {
        Budget::Seconds(s) => format!("{s} s"),
        Budget::Spp(n) => format!("{n} spp"),
    };
    let mut table = format!(
        "{name}, {} frames, {}x{}, {budget} per frame and way; relMSE against each frame's reference\n\n\
         | frame | method | from scratch | carried, tree kept | carried, tree refitted | refitted / scratch | refit drift |\n\
         | ---: | --- | ---: | ---: | ---: | ---: | ---: |\n",
        args.frames, settings.width, settings.height
    );
    let mut first_tree: Option<LightTree> = None;
    let mut refitted: Option<LightTree> = None;
    for f in 0..args.frames {
        let mut scene = animation::frame(&base, f);
        let reference = reference::load_or_render(
            &scene,
            &args.out,
            settings,
            reference_method,
            reference_budget,
            args.rebuild_reference,
        )?;
        let first = first_tree
            .get_or_insert_with(|| scene.light_tree.clone())
            .clone();
        let mut tree = refitted.take().unwrap_or_else(|| scene.light_tree.clone());
        let drift = tree
            .refit(scene.emitters.as_slice())
            .map_err(|e| format!("frame {f}: refit: {e}"))?;
        for &method in &methods {
            let relmse = |scene: &crate::scene::Scene, files: GuideFiles| {
                let s = Settings {
                    guide_files: files,
                    ..settings.clone()
                };
                let r = run::render(scene, method, &s);
                metrics::errors(&r.image, &reference).relmse
            };
            let scratch = relmse(&scene, GuideFiles::default());
            let mut carried = [0.0; 2];
            for (way, (label, light_tree)) in [("kept", &first), ("refitted", &tree)]
                .into_iter()
                .enumerate()
            {
                let files = GuideFiles {
                    load: (f > 0).then(|| dir.join(label)),
                    save: Some(dir.join(label)),
                    restart: true,
                };
                let built = std::mem::replace(&mut scene.light_tree, light_tree.clone());
                carried[way] = relmse(&scene, files);
                scene.light_tree = built;
            }
            writeln!(
                table,
                "| {f} | {} | {scratch:.4} | {:.4} | {:.4} | {:.2} | {drift:.3} |",
                method.name(),
                carried[0],
                carried[1],
                carried[1] / scratch
            )
            .expect("writing to a String");
            println!(
                "frame {f} {}: scratch {scratch:.4}, kept {:.4}, refitted {:.4}",
                method.name(),
                carried[0],
                carried[1]
            );
        }
        refitted = Some(tree);
    }
    std::fs::create_dir_all(args.out.join(name)).map_err(|e| e.to_string())?;
    let path = args.out.join(name).join("frames.md");
    std::fs::write(&path, &table).map_err(|e| format!("{}: {e}", path.display()))?;
    Ok(table)
}
