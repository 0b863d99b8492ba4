use std::time::Instant;

use glam::Vec3;

use lumiere::Result;
use lumiere::lights::LightSet;
use lumiere::scene::Scene;

use super::args::InfoArgs;

pub fn run(args: &InfoArgs) -> Result<()> {
    let start = Instant::now();
    let scene = Scene::load(&args.scene)?;
    let load_ms = start.elapsed().as_secs_f64() * 1e3;
    for warning in &scene.warnings {
        eprintln!("lumiere: warning: {warning}");
    }
    let bounds = scene.bounds();
    let lights = LightSet::new(&scene);
    let lights = lights.lights();
    let light_area: f32 = lights.iter().map(|l| l.area).sum();
    let light_power: Vec3 = lights.iter().map(|l| l.power()).sum();
    println!("scene      {}", scene.name);
    println!("triangles  {}", scene.mesh.triangle_count());
    println!("vertices   {}", scene.mesh.positions.len());
    println!("materials  {}", scene.materials.len());
    println!(
        "lights     {} triangles, area {light_area:.6}, power {:.6} {:.6} {:.6} W",
        lights.len(),
        light_power.x,
        light_power.y,
        light_power.z
    );
    if bounds.is_empty() {
        println!("bounds     empty");
    } else {
        println!(
            "bounds     ({:.6}, {:.6}, {:.6}) .. ({:.6}, {:.6}, {:.6})",
            bounds.min.x, bounds.min.y, bounds.min.z, bounds.max.x, bounds.max.y, bounds.max.z
        );
    }
    println!("load       {load_ms:.1} ms");
    Ok(())
}
