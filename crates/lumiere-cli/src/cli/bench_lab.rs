//! `lumiere bench`: the lab's timing table on the built-in scene, serial and parallel, beside the
//! lab's own figures.

use crate::bench::bvh::median_seconds;
use lumiere::integrators::{AmbientOcclusion, Direct, LightSampling, Shadows, Technique};
use lumiere::render::{RenderOptions, render};
use lumiere::scene::camera::Camera;
use lumiere::scene::{Scene, builtin};
use lumiere::util::write::{check_writable, write_atomically};
use lumiere::world::World;
use lumiere::{Error, Result};

use super::args::BenchLabArgs;
use super::output;
use super::technique_json::technique_json;
use lumiere::util::threads::pool;

/// One row of the lab's table: what was rendered and the lab's serial and parallel milliseconds.
struct LabRow {
    label: &'static str,
    technique: Technique,
    lab_serial_ms: f64,
    lab_parallel_ms: f64,
}

const LAB_ROWS: [LabRow; 7] = [
    LabRow {
        label: "hard shadows",
        technique: Technique::Shadows(Shadows),
        lab_serial_ms: 545.0,
        lab_parallel_ms: 272.0,
    },
    LabRow {
        label: "soft shadows N=16",
        technique: Technique::Direct(Direct { samples: 16, light_sampling: LightSampling::PerLight }),
        lab_serial_ms: 5902.0,
        lab_parallel_ms: 2891.0,
    },
    LabRow {
        label: "soft shadows N=64",
        technique: Technique::Direct(Direct { samples: 64, light_sampling: LightSampling::PerLight }),
        lab_serial_ms: 22697.0,
        lab_parallel_ms: 11506.0,
    },
    LabRow {
        label: "soft shadows N=256",
        technique: Technique::Direct(Direct { samples: 256, light_sampling: LightSampling::PerLight }),
        lab_serial_ms: 89203.0,
        lab_parallel_ms: 46847.0,
    },
    LabRow {
        label: "AO N=16",
        technique: Technique::AmbientOcclusion(AmbientOcclusion { samples: 16, distance: f32::INFINITY }),
        lab_serial_ms: 5295.0,
        lab_parallel_ms: 1817.0,
    },
    LabRow {
        label: "AO N=64",
        technique: Technique::AmbientOcclusion(AmbientOcclusion { samples: 64, distance: f32::INFINITY }),
        lab_serial_ms: 19188.0,
        lab_parallel_ms: 6954.0,
    },
    LabRow {
        label: "AO N=256",
        technique: Technique::AmbientOcclusion(AmbientOcclusion { samples: 256, distance: f32::INFINITY }),
        lab_serial_ms: 71066.0,
        lab_parallel_ms: 26914.0,
    },
];

pub fn run(args: &BenchLabArgs) -> Result<()> {
    // Refused now, not after minutes of measurement.
    if let Some(path) = &args.json {
        check_writable(path)?;
    }
    let (width, height, repeats) =
        if args.quick { (256, 192, 1) } else { (builtin::WIDTH, builtin::HEIGHT, args.repeats) };
    let world = World::with_isa(Scene::builtin()?, Default::default(), super::isa::choose(args.isa)?);
    let camera = Camera::from_orbiter(&builtin::cornell_orbiter()?, width, height);
    let all_cores = std::thread::available_parallelism().map_or(1, |n| n.get());
    let serial = pool(1)?;
    let parallel = pool(all_cores)?;

    // The lab's figures are for 1024x768: a quick run at another size prints no ratio to them.
    if args.quick {
        output::print(format_args!(
            "| image ({width}x{height}) | serial ms | parallel ms ({all_cores} threads) | rays | Mrays/s (parallel) |"
        ))?;
        output::print("|---|---|---|---|---|")?;
    } else {
        output::print(format_args!(
            "| image ({width}x{height}) | lab serial ms | serial ms | speed-up | lab parallel ms | parallel ms ({all_cores} threads) | speed-up | rays | Mrays/s (parallel) |"
        ))?;
        output::print("|---|---|---|---|---|---|---|---|---|")?;
    }
    let mut json = Vec::new();
    for row in &LAB_ROWS {
        let options = RenderOptions::new(row.technique);
        let mut rays = 0;
        let mut time = |pool: &rayon::ThreadPool| -> Result<f64> {
            let mut failure = None;
            let seconds = pool.install(|| {
                median_seconds(repeats, || match render(&world, &camera, &options, &|_| {}) {
                    Ok(out) => rays = out.stats.rays,
                    Err(e) => failure = Some(e),
                })
            });
            failure.map_or(Ok(seconds * 1e3), Err)
        };
        let serial_ms = time(&serial)?;
        let parallel_ms = time(&parallel)?;
        let mrays = rays as f64 / parallel_ms / 1e3;
        if args.quick {
            output::print(format_args!("| {} | {serial_ms:.0} | {parallel_ms:.0} | {rays} | {mrays:.1} |", row.label))?;
        } else {
            output::print(format_args!(
                "| {} | {:.0} | {serial_ms:.0} | {:.1}x | {:.0} | {parallel_ms:.0} | {:.1}x | {rays} | {mrays:.1} |",
                row.label,
                row.lab_serial_ms,
                row.lab_serial_ms / serial_ms,
                row.lab_parallel_ms,
                row.lab_parallel_ms / parallel_ms
            ))?;
            output::note(format_args!("bench: {} done", row.label));
        }
        // The lab's figures are of 1024x768 images: beside a --quick run's, a reader would divide them.
        let lab = |ms: f64| (!args.quick).then_some(ms);
        json.push(serde_json::json!({
            "image": row.label, "mode": row.technique.name(), "technique": technique_json(&row.technique), "width": width, "height": height,
            "repeats": repeats, "lab_serial_ms": lab(row.lab_serial_ms), "serial_ms": serial_ms,
            "lab_parallel_ms": lab(row.lab_parallel_ms), "parallel_ms": parallel_ms, "threads": all_cores,
            "rays": rays, "mrays_per_s": mrays,
        }));
    }
    if args.quick {
        output::print(format_args!(
            "\n(--quick: {width}x{height}, one run per row; no ratios to the lab's 1024x768 figures.)"
        ))?;
    }
    if let Some(path) = &args.json {
        let text = serde_json::to_string_pretty(&json).map_err(|e| Error::invalid(format!("json: {e}")))?;
        write_atomically(path, text.as_bytes())?;
    }
    Ok(())
}
