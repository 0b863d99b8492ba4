//! `lumiere bench-bvh`: build and traversal measurements on the benchmark scenes, as Markdown.

use std::time::Instant;

use crate::bench::bvh::{
    build, median_seconds, mesh_bytes, mismatches, peak_rss_mib, reset_peak_rss, trace, work_per_ray,
};
use crate::bench::rays::make_ray_sets;
use crate::bench::scenes::BenchScene;
use lumiere::accel::{BuildPreset, Bvh};
use lumiere::util::write::{check_writable, write_atomically};
use lumiere::world::World;
use lumiere::{Error, Result};

use super::args::BenchBvhArgs;
use super::export::{export_ray_sets, prepare_export_dir};
use super::output;
use lumiere::util::threads::{pool, resolved};

pub fn run(args: &BenchBvhArgs) -> Result<()> {
    let isa = super::isa::choose(args.isa)?;
    // Refused now, not after minutes of measurement.
    if let Some(path) = &args.json {
        check_writable(path)?;
    }
    let scenes: Vec<BenchScene> = args
        .scenes
        .split(',')
        .map(|name| {
            BenchScene::by_name(name.trim()).ok_or_else(|| {
                Error::invalid(format!("unknown benchmark scene '{name}' (cornell, bunny, bunny-1m, staircase)"))
            })
        })
        .collect::<Result<_>>()?;
    if let Some(dir) = &args.export_rays {
        prepare_export_dir(dir, &scenes.iter().map(|bench| bench.name).collect::<Vec<_>>())?;
    }
    // 0 is the count a pool of 0 starts (`RAYON_NUM_THREADS`, or one per core): the tables name it.
    let threads: Vec<usize> = args.threads.iter().map(|&n| resolved(n)).collect();
    let mut builds = Vec::new();
    let mut traces = Vec::new();
    let mut json = Vec::new();
    for bench in &scenes {
        reset_peak_rss();
        let start = Instant::now();
        let scene = bench.load(&args.scenes_dir)?;
        let load_ms = start.elapsed().as_secs_f64() * 1e3;
        let camera = bench.camera()?;
        let triangles = scene.mesh.triangle_count();
        let mesh = mesh_bytes(&scene.mesh);
        output::note(format_args!("{}: {triangles} triangles loaded in {load_ms:.0} ms", bench.name));

        // Reference structures and ray sets, built once.
        let binary = Bvh::build(&scene.mesh.positions, &scene.mesh.indices, BuildPreset::Default);
        let costs: Vec<String> = BuildPreset::ALL
            .iter()
            .map(|&p| format!("{:.1}", Bvh::build(&scene.mesh.positions, &scene.mesh.indices, p).sah_cost()))
            .collect();
        let world = World::with_isa(scene, BuildPreset::Default, isa);
        let sets = make_ray_sets(&world, &camera, args.seed);
        let bytes = mesh + world.accel().memory_bytes();
        for &n in &threads {
            let pool = pool(n)?;
            let build_ms = 1e3
                * pool.install(|| {
                    median_seconds(args.repeats, || drop(build(&world.scene().mesh, BuildPreset::Default, world.isa())))
                });
            builds.push(format!(
                "| {} | {} | {triangles} | {} | {load_ms:.0} | {build_ms:.0} | {} / {} | {} | {:.1} | {:.0} |",
                bench.name,
                n,
                binary.slot_count(),
                binary.nodes().len(),
                world.accel().node_count(),
                costs.join(" / "),
                bytes as f64 / triangles as f64,
                peak_rss_mib().unwrap_or(f64::NAN),
            ));
            json.push(serde_json::json!({"scene": bench.name, "threads": n, "what": "build", "triangles": triangles, "references": binary.slot_count(), "load_ms": load_ms, "build_ms": build_ms, "binary_nodes": binary.nodes().len(), "wide_nodes": world.accel().node_count(), "bytes_per_triangle": bytes as f64 / triangles as f64}));
        }
        for set in &sets {
            let wrong = mismatches(&binary, world.accel(), set);
            let (nodes, blocks) = work_per_ray(world.accel(), set);
            for &n in &threads {
                let seconds = pool(n)?.install(|| median_seconds(args.repeats, || trace(world.accel(), set)));
                let mrays = set.rays.len() as f64 / seconds / 1e6;
                traces.push(format!(
                    "| {} | {} {} | {} | {} | {:.1} | {mrays:.1} | {nodes:.1} | {blocks:.1} | {wrong} |",
                    bench.name,
                    set.kind,
                    set.query.name(),
                    n,
                    set.rays.len(),
                    seconds * 1e3,
                ));
                json.push(serde_json::json!({"scene": bench.name, "threads": n, "what": "trace", "kind": set.kind, "query": set.query.name(), "rays": set.rays.len(), "median_s": seconds, "mrays_per_s": mrays, "nodes_per_ray": nodes, "blocks_per_ray": blocks, "mismatches": wrong}));
                if wrong != 0 {
                    output::warn(format_args!(
                        "{} {} {}: {wrong} rays differ from the scalar reference",
                        bench.name,
                        set.kind,
                        set.query.name()
                    ));
                }
            }
        }
        if let Some(dir) = &args.export_rays {
            export_ray_sets(&dir.join(bench.name), &world, &sets)?;
        }
    }
    output::print(
        "| scene | threads | triangles | references | load ms | build ms | nodes binary / wide | SAH fast / default / high | bytes/tri | peak RSS MiB (during the scene) |",
    )?;
    output::print("|---|---|---|---|---|---|---|---|---|---|")?;
    for row in &builds {
        output::print(row)?;
    }
    output::print("")?;
    output::print("| scene | rays | threads | count | median ms | Mrays/s | nodes/ray | blocks/ray | mismatches |")?;
    output::print("|---|---|---|---|---|---|---|---|---|")?;
    for row in &traces {
        output::print(row)?;
    }
    if let Some(path) = &args.json {
        let text = serde_json::to_string_pretty(&json).map_err(|e| Error::invalid(format!("json: {e}")))?;
        write_atomically(path, text.as_bytes())?;
    }
    Ok(())
}
