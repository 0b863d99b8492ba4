//! `lumiere info`: what is in a scene — counts, materials by name (what `--emission` needs) with
//! the scattering each maps to and their textures, lights, bounds — and its load warnings.

use std::fmt::Display;
use std::path::Path;
use std::time::Instant;

use glam::Vec3;

use lumiere::Result;
use lumiere::error::quote;
use lumiere::lights::LightSet;
use lumiere::materials::{CoverageTest, Cut, Material, MaterialKind, Relief};
use lumiere::math::UvTransform;
use lumiere::scene::Scene;
use lumiere::scene::camera::View;
use lumiere::textures::{TextureSet, TextureUse};

use super::args::InfoArgs;
use super::output;

pub fn run(args: &InfoArgs) -> Result<()> {
    let start = Instant::now();
    let scene = match &args.scene {
        Some(path) => Scene::load(path)?,
        None => Scene::builtin()?,
    };
    let load_ms = start.elapsed().as_secs_f64() * 1e3;
    for warning in &scene.warnings {
        output::warn(warning);
    }
    // Named as a render would name them, from their metadata: a render decodes them when it
    // builds the world, and a user asking why a surface comes out plain learns it here.
    let materials = &scene.materials;
    for warning in materials.iter().filter_map(Material::ignored_mask_warning) {
        output::warn(warning);
    }
    for warning in TextureSet::unreadable_files(textures_named(materials), &scene.embedded_images) {
        output::warn(warning);
    }
    let lights = LightSet::new(&scene);
    let lights = lights.lights();
    let light_area: f32 = lights.iter().map(|l| l.area).fold(0.0, |a, b| a + b);
    let light_power: Vec3 = lights.iter().map(|l| l.power()).fold(Vec3::ZERO, |a, b| a + b);
    line("scene", &scene.name)?;
    line("triangles", scene.mesh.triangle_count())?;
    line("vertices", scene.mesh.positions.len())?;
    line("normals", if scene.mesh.normal_indices.is_empty() { "none" } else { "per vertex (vn)" })?;
    line("texcoords", if scene.mesh.texcoord_indices.is_empty() { "none" } else { "per vertex (vt)" })?;
    line(
        "lights",
        format!("{} triangles, area {}, power {} W", lights.len(), number(light_area), vector(light_power)),
    )?;
    let bounds = scene.bounds();
    if bounds.is_empty() {
        line("bounds", "empty")?;
    } else {
        line("bounds", format!("{} .. {}", vector(bounds.min), vector(bounds.max)))?;
    }
    if let Some(view) = &scene.view {
        line("view", described_view(view))?;
    }
    line("load", format!("{load_ms:.1} ms"))?;
    line("materials", scene.materials.len())?;
    let mut triangles = vec![0usize; scene.materials.len()];
    for &id in &scene.mesh.material_ids {
        triangles[id as usize] += 1;
    }
    for (material, triangles) in scene.materials.iter().zip(triangles) {
        output::print(format_args!("  {:?}: {triangles} triangles, {}", material.name, describe(material)))?;
    }
    Ok(())
}

/// Every texture file `materials` name, with its use, in the order a render decodes them.
fn textures_named(materials: &[Material]) -> impl Iterator<Item = (TextureUse, Option<&Path>)> {
    let diffuse = materials.iter().map(|m| (TextureUse::Diffuse, m.map_kd.as_deref()));
    let coverage = materials.iter().map(|m| (TextureUse::Coverage, m.cutout_mask()));
    let parameters = materials.iter().flat_map(|m| [&m.map_pm, &m.map_pr]);
    let parameters = parameters.map(|map| (TextureUse::Parameters, map.as_ref().map(|map| map.path.as_path())));
    let normals = materials.iter().map(|m| (TextureUse::Normals, m.normal_map.as_ref().map(|map| map.path.as_path())));
    diffuse.chain(coverage).chain(parameters).chain(normals)
}

fn line(key: &str, value: impl Display) -> Result<()> {
    output::print(format_args!("{key:<11}{value}"))
}

/// What lumiere uses of a material: the scattering its statements map to (docs/MATERIALS.md), its
/// colour, its texture, the maps that paint its metallic weight and roughness, its normal map,
/// its cutout mask, its emission.
fn describe(material: &Material) -> String {
    let kind = material.kind();
    let details = match kind {
        MaterialKind::Lambert => None,
        MaterialKind::Plastic { ks, alpha } => Some(format!("Ks {}, alpha {}", vector(ks), number(alpha))),
        MaterialKind::Conductor { alpha } => Some(format!("F0 the base colour, alpha {}", number(alpha))),
        MaterialKind::Mirror { f0 } => Some(format!("F0 {}", vector(f0))),
        MaterialKind::Dielectric { eta, tf } => Some(format!("eta {}, Tf {}", number(eta), vector(tf))),
    };
    let scattering = match (painted_scattering(material), details) {
        (Some(painted), _) => painted,
        (None, Some(details)) => format!("{} ({details})", kind.name()),
        (None, None) => kind.name().to_string(),
    };
    let mut parts = vec![scattering];
    // A mirror of `Ks` and glass ignore the base colour.
    if !matches!(kind, MaterialKind::Mirror { .. } | MaterialKind::Dielectric { .. }) {
        parts.push(format!("Kd {}", vector(material.kd)));
        if let Some(texture) = &material.map_kd {
            let factor = material.map_kd_factor;
            let tint = if factor == Vec3::ONE { String::new() } else { format!(" x {}", vector(factor)) };
            let path = texture.display().to_string();
            parts.push(format!("map_Kd {}{path:?}{tint}", placement(material.map_kd_transform)));
        }
    }
    for (keyword, map) in [("map_Pm", &material.map_pm), ("map_Pr", &material.map_pr)] {
        if let Some(map) = map {
            let channel = format!("{:?}", map.channel).to_lowercase();
            let path = map.path.display().to_string();
            parts.push(format!("{keyword} {}{path:?} ({channel} x {})", placement(map.transform), number(map.scale)));
        }
    }
    if let Some(map) = &material.normal_map {
        let (path, at) = (map.path.display().to_string(), placement(map.transform));
        parts.push(match map.relief {
            Relief::Directions => format!("normal map {at}{path:?} (scale {})", number(map.scale)),
            Relief::Heights { channel } => format!(
                "bump map {at}{path:?} (heights: {} x {}; directions if the image has a normal map's colours)",
                format!("{channel:?}").to_lowercase(),
                number(map.scale)
            ),
        });
    }
    let test = material.map_d_test;
    if let Some(mask) = material.cutout_mask() {
        let cut = if test == CoverageTest::MTL { "cutout".to_string() } else { cut(test, "its alpha") };
        parts.push(format!("map_d {}{:?} ({cut})", placement(material.map_d_transform), mask.display().to_string()));
    } else if !test.keeps_full_coverage() && !material.is_emissive() {
        // Without a texture the factor alone is the coverage (MTL's `d`, glTF's alpha).
        parts.push(match test.cut {
            Cut::Hashed => format!("covering {} of the surface, hashed", number(test.scale)),
            Cut::Below(_) => cut(test, "coverage"),
        });
    }
    if material.is_emissive() {
        parts.push(format!("Ke {} (a light)", vector(material.ke)));
    }
    parts.join(", ")
}

/// The scattering of a PBR material whose metallic weight or roughness a map paints, which
/// varies over its surface: `None` for the others.
fn painted_scattering(material: &Material) -> Option<String> {
    if material.map_pm.is_none() && material.map_pr.is_none() {
        return None;
    }
    let alpha = if material.map_pr.is_some() {
        "alpha from map_Pr".to_string()
    } else {
        format!("alpha {}", number(material.pbr_alpha()))
    };
    // Without a metallic map, the constants' kind (`Material::kind`'s threshold) holds everywhere.
    Some(match (&material.map_pm, material.kind()) {
        (Some(_), _) => format!("conductor where map_Pm reaches 0.5, plastic (Ks 0.04) elsewhere ({alpha})"),
        (None, MaterialKind::Conductor { .. }) => format!("conductor (F0 the base colour, {alpha})"),
        (None, _) => format!("plastic (Ks 0.04, {alpha})"),
    })
}

/// How a coverage test other than MTL's cuts: `coverage` names what it reads.
fn cut(test: CoverageTest, coverage: &str) -> String {
    match test.cut {
        Cut::Below(threshold) => {
            format!("cut out where {coverage} x {} is below {}", number(test.scale), number(threshold))
        }
        Cut::Hashed => format!("covering {coverage} x {} of the surface, hashed", number(test.scale)),
    }
}

/// The scene file's own view as `--eye`, `--target`, `--up` and `--fov` would give it.
fn described_view(view: &View) -> String {
    let name = view.name.as_deref().map(|name| format!("{} ", quote(name))).unwrap_or_default();
    format!(
        "{name}eye {}, target {}, up {}, fov {} degrees",
        vector(view.eye),
        vector(view.target),
        vector(view.up),
        number(view.fov_degrees)
    )
}

/// A texture's `-s` and `-o` as the MTL writes them, where they move it.
fn placement(transform: UvTransform) -> String {
    if transform.is_identity() {
        return String::new();
    }
    let (s, o) = (transform.scale, transform.offset);
    format!("-s {} {} -o {} {} ", number(s.x), number(s.y), number(o.x), number(o.y))
}

/// Six decimals, and `0` never printed as `-0`.
fn number(x: f32) -> String {
    format!("{:.6}", if x == 0.0 { 0.0 } else { x })
}

fn vector(v: Vec3) -> String {
    format!("({}, {}, {})", number(v.x), number(v.y), number(v.z))
}
