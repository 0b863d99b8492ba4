use std::time::Instant;

use glam::Vec3;

use lumiere::Result;
use lumiere::lights::LightSet;
use lumiere::scene::Scene;

use super::args::InfoArgs;
use super::output;

pub fn run(args: &InfoArgs) -> Result<()> {
    let start = Instant::now();
    let scene = Scene::load(&args.scene)?;
    let load_ms = start.elapsed().as_secs_f64() * 1e3;
    for warning in &scene.warnings {
        output::warn(format_args!("{warning}"));
    }
    let bounds = scene.bounds();
    let lights = LightSet::new(&scene);
    let lights = lights.lights();
    let light_area: f32 = lights.iter().map(|l| l.area).sum();
    let light_power: Vec3 = lights.iter().map(|l| l.power()).sum();
    output::print(format_args!("scene      {}", scene.name))?;
    output::print(format_args!("triangles  {}", scene.mesh.triangle_count()))?;
    output::print(format_args!("vertices   {}", scene.mesh.positions.len()))?;
    output::print(format_args!("materials  {}", scene.materials.len()))?;
    output::print(format_args!(
        "lights     {} triangles, area {light_area:.6}, power {:.6} {:.6} {:.6} W",
        lights.len(),
        light_power.x,
        light_power.y,
        light_power.z
    ))?;
    if bounds.is_empty() {
        output::print(format_args!("bounds     empty"))?;
    } else {
        output::print(format_args!(
            "bounds     ({:.6}, {:.6}, {:.6}) .. ({:.6}, {:.6}, {:.6})",
            bounds.min.x, bounds.min.y, bounds.min.z, bounds.max.x, bounds.max.y, bounds.max.z
        ))?;
    }
    output::print(format_args!("load       {load_ms:.1} ms"))?;
    Ok(())
}
