//! MTL (material library) parsing. Lenient by design: a bad line costs a warning, not the scene,
//! because a render with one wrong material is more useful than no render.

use super::text::{Tokens, finite_f32, lines, quoted};
use crate::error::{quote, shown_path};
use crate::materials::Material;
use crate::scene::load::warnings::Warnings;
use glam::Vec3;
use std::path::{Path, PathBuf};

/// Parses the MTL file read from `path` into its materials, in file order, with one warning per
/// line that was ignored (capped, see [`Warnings`]); `map_Kd` and `map_d` files resolve relative to its folder.
pub(super) fn parse_mtl(bytes: &[u8], path: &Path, warnings: &mut Warnings) -> Vec<Material> {
    let folder = path.parent().unwrap_or(Path::new(""));
    let mut materials: Vec<Material> = Vec::new();
    // Per material, the keywords of the statements it carries that lumiere does not render.
    let mut unsupported: Vec<Vec<String>> = Vec::new();
    for (i, line) in lines(bytes).enumerate() {
        let problem = match parse_statement(line, folder) {
            Ok(None) => continue,
            Ok(Some(Statement::NewMtl(name))) => {
                materials.push(Material::default_grey(&name));
                unsupported.push(Vec::new());
                continue;
            }
            Ok(Some(Statement::Unsupported(keyword))) if !materials.is_empty() => {
                let ignored = unsupported.last_mut().expect("one list per material");
                if !ignored.contains(&keyword) {
                    ignored.push(keyword);
                }
                continue;
            }
            Ok(Some(statement)) => match materials.last_mut() {
                Some(material) => {
                    statement.apply(material);
                    continue;
                }
                None => "statement before the first newmtl".to_string(),
            },
            Err(message) => message,
        };
        warnings.push(path, "ignored MTL lines", || format!("{}:{}: {problem}; line ignored", shown_path(path), i + 1));
    }
    for (material, ignored) in materials.iter().zip(&unsupported).filter(|(_, ignored)| !ignored.is_empty()) {
        let keywords: Vec<String> = ignored.iter().map(quote).collect();
        warnings.push(path, "unsupported MTL statements", || {
            format!(
                "{}: material {} uses statements lumiere does not render: {} (see docs/MATERIALS.md)",
                shown_path(path),
                quote(&material.name),
                keywords.join(", ")
            )
        });
    }
    materials
}

/// The MTL statements we keep; the others are named in one warning per material (`Ka` aside).
enum Statement {
    NewMtl(String),
    Diffuse(Vec3),
    Specular(Vec3),
    Emission(Vec3),
    Shininess(f32),
    RefractiveIndex(f32),
    Dissolve(f32),
    Illumination(u32),
    DiffuseMap(PathBuf),
    CoverageMap(PathBuf),
    TransmissionFilter(Vec3),
    Metallic(f32),
    Roughness(f32),
    /// A statement lumiere does not render (bump maps, specular maps, ...), by keyword.
    Unsupported(String),
}

impl Statement {
    fn apply(self, material: &mut Material) {
        match self {
            Statement::NewMtl(name) => material.name = name,
            Statement::Diffuse(kd) => material.kd = kd,
            Statement::Specular(ks) => material.ks = ks,
            Statement::Emission(ke) => material.ke = ke,
            Statement::Shininess(ns) => material.ns = ns,
            Statement::RefractiveIndex(ni) => material.ni = ni,
            Statement::Dissolve(d) => material.dissolve = d,
            Statement::Illumination(illum) => material.illum = illum,
            Statement::DiffuseMap(path) => material.map_kd = Some(path),
            Statement::CoverageMap(path) => material.map_d = Some(path),
            Statement::TransmissionFilter(tf) => material.tf = tf,
            Statement::Metallic(pm) => material.metallic = Some(pm),
            Statement::Roughness(pr) => material.roughness = Some(pr),
            Statement::Unsupported(_) => {}
        }
    }
}

/// Statements that are ignored without a word: ambient colour and its map.
const HARMLESS: [&[u8]; 2] = [b"Ka", b"map_Ka"];

/// `Ok(None)` for blank lines, comments and ambient terms.
fn parse_statement(line: &[u8], folder: &Path) -> Result<Option<Statement>, String> {
    let mut tokens = Tokens::new(line);
    let Some(keyword) = tokens.next() else {
        return Ok(None);
    };
    let statement = match keyword {
        b"newmtl" => Statement::NewMtl(material_name(tokens)?),
        b"Kd" => Statement::Diffuse(color(tokens)?),
        b"Ks" => Statement::Specular(color(tokens)?),
        b"Ke" => Statement::Emission(color(tokens)?),
        b"Ns" => Statement::Shininess(scalar(tokens)?),
        b"Ni" => Statement::RefractiveIndex(scalar(tokens)?),
        // `d -halo 0.5` is an old variant; the halo itself is ignored.
        b"d" => Statement::Dissolve(scalar(tokens.skip_while(|&token| token == b"-halo"))?),
        b"Tr" => Statement::Dissolve(1.0 - scalar(tokens)?),
        b"illum" => Statement::Illumination(integer(tokens)?),
        b"map_Kd" => Statement::DiffuseMap(texture_path("map_Kd", tokens, folder)?),
        b"map_d" => Statement::CoverageMap(texture_path("map_d", tokens, folder)?),
        b"Tf" => Statement::TransmissionFilter(color(tokens)?),
        b"Pm" => Statement::Metallic(scalar(tokens)?),
        b"Pr" => Statement::Roughness(scalar(tokens)?),
        // Comments, and ambient terms, which have no meaning in a physically based renderer.
        keyword if keyword.starts_with(b"#") || HARMLESS.contains(&keyword) => return Ok(None),
        keyword => Statement::Unsupported(String::from_utf8_lossy(keyword).into_owned()),
    };
    Ok(Some(statement))
}

fn material_name(tokens: Tokens) -> Result<String, String> {
    let name = tokens.remainder();
    if name.is_empty() {
        return Err("newmtl without a name".to_string());
    }
    Ok(name.into_owned())
}

/// `r g b`, or a single value for grey, as the MTL format allows.
fn color<'a>(tokens: impl Iterator<Item = &'a [u8]>) -> Result<Vec3, String> {
    let values = tokens.map(finite_f32).collect::<Result<Vec<_>, _>>()?;
    match values[..] {
        [grey] => Ok(Vec3::splat(grey)),
        [r, g, b] => Ok(Vec3::new(r, g, b)),
        _ => Err(format!("expected 1 or 3 numbers, found {}", values.len())),
    }
}

fn scalar<'a>(mut tokens: impl Iterator<Item = &'a [u8]>) -> Result<f32, String> {
    match (tokens.next(), tokens.next()) {
        (Some(token), None) => finite_f32(token),
        _ => Err("expected exactly one number".to_string()),
    }
}

fn integer<'a>(mut tokens: impl Iterator<Item = &'a [u8]>) -> Result<u32, String> {
    match (tokens.next(), tokens.next()) {
        (Some(token), None) => std::str::from_utf8(token)
            .ok()
            .and_then(|text| text.parse().ok())
            .ok_or_else(|| format!("malformed integer {}", quoted(token))),
        _ => Err("expected exactly one integer".to_string()),
    }
}

/// The texture file is the last token: options such as `-bm 1` or `-o 0 0 0` come before it.
/// Backslashes become slashes, since files exported on Windows use them as separators.
fn texture_path<'a>(keyword: &str, tokens: impl Iterator<Item = &'a [u8]>, folder: &Path) -> Result<PathBuf, String> {
    let file = tokens.last().ok_or_else(|| format!("{keyword} without a file name"))?;
    let file = String::from_utf8_lossy(file).replace('\\', "/");
    Ok(folder.join(file))
}
