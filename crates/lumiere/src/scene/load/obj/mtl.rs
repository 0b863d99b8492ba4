//! MTL (material library) parsing. Lenient by design: a bad line costs a warning, not the scene,
//! because a render with one wrong material is more useful than no render.

use super::text::{Tokens, finite_f32, lines, quoted};
use crate::error::shown_path;
use crate::materials::Material;
use crate::scene::load::warnings::Warnings;
use glam::Vec3;
use std::path::{Path, PathBuf};

/// Parses the MTL file read from `path` into its materials, in file order, with one warning per
/// line that was ignored (capped, see [`Warnings`]); `map_Kd` files resolve relative to its folder.
pub(super) fn parse_mtl(bytes: &[u8], path: &Path, warnings: &mut Warnings) -> Vec<Material> {
    let folder = path.parent().unwrap_or(Path::new(""));
    let mut materials: Vec<Material> = Vec::new();
    for (i, line) in lines(bytes).enumerate() {
        let problem = match parse_statement(line, folder) {
            Ok(None) => continue,
            Ok(Some(Statement::NewMtl(name))) => {
                materials.push(Material::default_grey(&name));
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
    materials
}

/// The MTL statements we keep; everything else (`Ka`, `map_Bump`, ...) is skipped silently.
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
        }
    }
}

/// `Ok(None)` for blank lines, comments and statements we do not use.
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
        b"map_Kd" => Statement::DiffuseMap(texture_path(tokens, folder)?),
        _ => return Ok(None),
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
fn texture_path<'a>(tokens: impl Iterator<Item = &'a [u8]>, folder: &Path) -> Result<PathBuf, String> {
    let file = tokens.last().ok_or("map_Kd without a file name")?;
    let file = String::from_utf8_lossy(file).replace('\\', "/");
    Ok(folder.join(file))
}
