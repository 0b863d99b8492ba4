//! MTL (material library) parsing. Lenient by design: a bad line costs a warning, not the scene,
//! because a render with one wrong material is more useful than no render.

use super::continued::{has_continuations, joined};
use super::text::{LONE_CARRIAGE_RETURNS, Tokens, finite_f32, has_lone_carriage_returns, lines};
use crate::error::{quote, shown_path};
use crate::materials::{CoverageTest, Cut, Material, MaterialKind, NormalMap, ParameterMap, Relief};
use crate::math::UvTransform;
use crate::scene::load::path_from_bytes;
use crate::scene::load::warnings::Warnings;
use crate::textures::Channel;
use glam::Vec3;
use std::path::{Path, PathBuf};

/// Parses the MTL file read from `path` into its materials, in file order, with one warning per
/// line that was ignored (capped, see [`Warnings`]); texture files resolve relative to its folder.
pub(super) fn parse_mtl(bytes: &[u8], path: &Path, warnings: &mut Warnings) -> Vec<Material> {
    let folder = path.parent().unwrap_or(Path::new(""));
    // Editors on Windows may start the file with a UTF-8 byte-order mark.
    let bytes = bytes.strip_prefix(b"\xEF\xBB\xBF").unwrap_or(bytes);
    // A NUL never occurs in text: one warning for the file, not one per line of binary data.
    if let Some(at) = bytes.iter().position(|&b| b == 0) {
        let line = 1 + bytes[..at].iter().filter(|&&b| b == b'\n').count();
        warnings.push(path, "binary MTL files", || {
            format!(
                "{}:{line}: a NUL byte: binary data, not an MTL text file; its materials are not read",
                shown_path(path)
            )
        });
        return Vec::new();
    }
    if has_lone_carriage_returns(bytes) {
        warnings.push(path, "MTL files with lone carriage returns", || {
            format!("{}:1: {LONE_CARRIAGE_RETURNS}; its materials are not read", shown_path(path))
        });
        return Vec::new();
    }
    // Statements continued with a trailing backslash, joined as in the OBJ file (line numbers kept).
    let joined = match has_continuations(bytes).then(|| joined(bytes)) {
        None => None,
        Some(Ok(joined)) => Some(joined),
        Some(Err(_)) => {
            warnings.push(path, "MTL files too large to join", || {
                format!(
                    "{}: joining its continued lines needs more memory than is left; its materials are not read",
                    shown_path(path)
                )
            });
            return Vec::new();
        }
    };
    let bytes = joined.as_deref().unwrap_or(bytes);
    let mut materials: Vec<(Material, Notes)> = Vec::new();
    // After a `newmtl` without a name, whose statements belong to no material we could name.
    let mut nameless = false;
    for (i, line) in lines(bytes).enumerate() {
        let problem = match parse_statement(line, folder) {
            Ok(None) => continue,
            Ok(Some(Statement::NewMtl(name))) => {
                materials.push((Material::default_grey(&name), Notes::default()));
                nameless = false;
                continue;
            }
            Ok(Some(Statement::NamelessMtl)) => {
                // Applied to the material before it, they would overwrite its values. Readers
                // drop them too: tinyobjloader keeps no material of an empty name.
                nameless = true;
                "newmtl without a name: its statements, up to the next newmtl, are not read".to_string()
            }
            Ok(Some(_)) if nameless => continue,
            Ok(Some(statement)) => match materials.last_mut() {
                Some((material, notes)) => {
                    for option in statement.texture_options() {
                        notes.note_unsupported(option);
                    }
                    statement.apply(material, notes);
                    if let Some(clamped) = material.clamp_kd() {
                        warnings.push(path, "clamped colours", || {
                            format!("{}:{}: material {}: {clamped}", shown_path(path), i + 1, quote(&material.name))
                        });
                    }
                    continue;
                }
                None => "statement before the first newmtl".to_string(),
            },
            Err(message) => message,
        };
        warnings.push(path, "ignored MTL lines", || format!("{}:{}: {problem}; line ignored", shown_path(path), i + 1));
    }
    let finish = |(mut material, notes): (Material, Notes)| {
        let mut ignored = notes.unsupported;
        // Without `d`, a coverage below 1 can only have come from `Tr`.
        let below_one = if notes.has_d { "\"d\" below 1" } else { "\"Tr\" above 0" };
        match partial_coverage(&mut material) {
            Coverage::Whole | Coverage::Partial => {}
            Coverage::None => warnings.push(path, "materials of no coverage", || {
                // The statement as the file wrote it.
                let none = if notes.has_d {
                    format!("\"d {}\"", material.dissolve)
                } else {
                    format!("\"Tr {}\"", 1.0 - material.dissolve)
                };
                format!(
                    "{}: material {}: {none} leaves none of its surface: it is not seen",
                    shown_path(path),
                    quote(&material.name)
                )
            }),
            Coverage::LightKeptWhole => ignored.push(format!("{below_one} on an emitter (a light is whole)")),
        }
        ignored.extend(unrendered_values(&material));
        if !ignored.is_empty() {
            warnings.push(path, "unsupported MTL statements", || {
                format!(
                    "{}: material {} uses statements lumiere does not render: {} (see docs/MATERIALS.md)",
                    shown_path(path),
                    quote(&material.name),
                    ignored.join(", ")
                )
            });
        }
        material
    };
    materials.into_iter().map(finish).collect()
}

/// What parsing learns of a material besides its values.
#[derive(Default)]
struct Notes {
    /// What it carries that lumiere does not render: unknown statements' keywords (quoted) and
    /// texture options, each once.
    unsupported: Vec<String>,
    /// Whether a `d` statement set its coverage: a `Tr` then changes nothing, before or after it.
    has_d: bool,
    /// The keyword of the statement that gave the material its normal map (`norm`, `bump`, ...):
    /// `norm` wins over a bump map, before or after it.
    relief_from: Option<&'static str>,
}

impl Notes {
    /// Adds `what` to the material's list of what it does not get, once.
    fn note_unsupported(&mut self, what: String) {
        if !self.unsupported.contains(&what) {
            self.unsupported.push(what);
        }
    }
}

/// What a material's `d` (or `Tr`) makes of its surface.
enum Coverage {
    /// All of it is there: `d 1`, glass (whose `d` says it transmits), or a `map_d` cutout (whose
    /// texture says where the surface is).
    Whole,
    /// The share `d` of it, hashed (docs/MATERIALS.md, "Cutouts").
    Partial,
    /// None of it (`d 0`).
    None,
    /// An emitter's, which stays whole whatever its `d`.
    LightKeptWhole,
}

/// Reads a `d` below 1 on a surface that is neither glass nor cut out by `map_d` as partial
/// coverage, as Blender reads it (an alpha): the share `d` of the surface is there, each point kept
/// or cut by a hash of it, as glTF's `BLEND`, so that a veil of `d 0.3` stops 30% of the rays that
/// meet it. A light stays whole (`Material::cutout_mask` says why).
fn partial_coverage(material: &mut Material) -> Coverage {
    let glass = matches!(material.kind(), MaterialKind::Dielectric { .. });
    if glass || material.dissolve >= 1.0 || material.map_d.is_some() {
        return Coverage::Whole;
    }
    if material.is_emissive() {
        return Coverage::LightKeptWhole;
    }
    let share = material.dissolve.max(0.0);
    material.map_d_test = CoverageTest { alpha_only: false, scale: share, cut: Cut::Hashed };
    if share > 0.0 { Coverage::Partial } else { Coverage::None }
}

/// Statements lumiere reads but whose value, on this material, has no effect (docs/MATERIALS.md,
/// "Not honoured"): a transmission filter on an opaque material, an illumination model beyond 9.
fn unrendered_values(material: &Material) -> Vec<String> {
    let glass = matches!(material.kind(), MaterialKind::Dielectric { .. });
    let mut notes = Vec::new();
    if !glass && material.tf != Vec3::ONE {
        notes.push("\"Tf\" (only glass filters light)".to_string());
    }
    if material.illum > 9 {
        notes.push(quote(format!("illum {}", material.illum)));
    }
    notes
}

/// The MTL statements we keep; the others are named in one warning per material (`Ka` aside).
enum Statement {
    NewMtl(String),
    /// A `newmtl` without a name.
    NamelessMtl,
    Diffuse(Vec3),
    Specular(Vec3),
    Emission(Vec3),
    Shininess(f32),
    RefractiveIndex(f32),
    Dissolve(f32),
    /// `Tr`, transparency: coverage `1 - Tr` where the material has no `d`.
    Transparency(f32),
    Illumination(u32),
    DiffuseMap(TextureMap),
    CoverageMap(TextureMap),
    TransmissionFilter(Vec3),
    Metallic(f32),
    Roughness(f32),
    MetallicMap(TextureMap),
    RoughnessMap(TextureMap),
    /// `norm` (a normal map) or `bump`, `map_Bump`, `map_bump` (a height map), by its keyword.
    ReliefMap(TextureMap, &'static str),
    /// A statement lumiere does not render (displacement and specular maps, ...), by keyword.
    Unsupported(String),
}

impl Statement {
    /// The options of a texture statement that lumiere does not honour (`map_Kd -bm 1 …`), each
    /// as `"map_Kd -bm"`: they cost a warning, since they change what a surface looks like.
    fn texture_options(&self) -> Vec<String> {
        let (keyword, options) = match self {
            Statement::DiffuseMap(map) => ("map_Kd", &map.options),
            Statement::CoverageMap(map) => ("map_d", &map.options),
            Statement::MetallicMap(map) => ("map_Pm", &map.options),
            Statement::RoughnessMap(map) => ("map_Pr", &map.options),
            Statement::ReliefMap(map, keyword) => (*keyword, &map.options),
            _ => return Vec::new(),
        };
        options.iter().map(|option| quote(format!("{keyword} {option}"))).collect()
    }

    fn apply(self, material: &mut Material, notes: &mut Notes) {
        match self {
            Statement::Diffuse(kd) => material.kd = kd,
            Statement::Specular(ks) => material.ks = ks,
            Statement::Emission(ke) => material.ke = ke,
            Statement::Shininess(ns) => material.ns = ns,
            Statement::RefractiveIndex(ni) => material.ni = ni,
            // `d` wins over `Tr` whatever their order, as tinyobjloader reads them: 3ds Max writes
            // both, with a `Tr` that some versions meant as `d` itself.
            Statement::Dissolve(d) => (material.dissolve, notes.has_d) = (d, true),
            Statement::Transparency(tr) if !notes.has_d => material.dissolve = 1.0 - tr,
            Statement::Illumination(illum) => material.illum = illum,
            Statement::DiffuseMap(map) => {
                (material.map_kd, material.map_kd_transform) = (Some(map.path), map.transform)
            }
            Statement::CoverageMap(map) => (material.map_d, material.map_d_transform) = (Some(map.path), map.transform),
            Statement::TransmissionFilter(tf) => material.tf = tf,
            Statement::Metallic(pm) => material.metallic = Some(pm),
            Statement::Roughness(pr) => material.roughness = Some(pr),
            Statement::MetallicMap(map) => material.map_pm = Some(map.into_parameter()),
            Statement::RoughnessMap(map) => material.map_pr = Some(map.into_parameter()),
            Statement::ReliefMap(map, keyword) => {
                // `norm` wins over a bump map whatever their order, as `d` over `Tr`: the two
                // describe one relief, and a normal map is the finer description of it.
                let (kept, dropped) = match notes.relief_from {
                    Some("norm") if keyword != "norm" => (None, Some(keyword)),
                    Some(earlier) if keyword == "norm" && earlier != "norm" => (Some(map), Some(earlier)),
                    _ => (Some(map), None),
                };
                if let Some(dropped) = dropped {
                    notes.note_unsupported(format!("{} (norm is used)", quote(dropped)));
                }
                if let Some(map) = kept {
                    material.normal_map = Some(map.into_relief(keyword));
                    notes.relief_from = Some(keyword);
                }
            }
            Statement::Unsupported(keyword) => notes.note_unsupported(quote(&keyword)),
            Statement::NewMtl(_) | Statement::NamelessMtl | Statement::Transparency(_) => {}
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
        b"newmtl" => material_name(tokens).map_or(Statement::NamelessMtl, Statement::NewMtl),
        b"Kd" => Statement::Diffuse(color(tokens)?),
        b"Ks" => Statement::Specular(color(tokens)?),
        b"Ke" => Statement::Emission(emission(tokens)?),
        b"Ns" => Statement::Shininess(scalar(tokens)?),
        b"Ni" => Statement::RefractiveIndex(scalar(tokens)?),
        // `d -halo 0.5` is an old variant; the halo itself is ignored.
        b"d" => Statement::Dissolve(scalar(tokens.skip_while(|&token| token == b"-halo"))?),
        b"Tr" => Statement::Transparency(scalar(tokens)?),
        b"illum" => Statement::Illumination(illumination(tokens)?),
        b"map_Kd" => Statement::DiffuseMap(texture_map("map_Kd", tokens, folder)?),
        b"map_d" => Statement::CoverageMap(texture_map("map_d", tokens, folder)?),
        b"Tf" => Statement::TransmissionFilter(color(tokens)?),
        b"Pm" => Statement::Metallic(scalar(tokens)?),
        b"Pr" => Statement::Roughness(scalar(tokens)?),
        b"map_Pm" => Statement::MetallicMap(texture_map("map_Pm", tokens, folder)?),
        b"map_Pr" => Statement::RoughnessMap(texture_map("map_Pr", tokens, folder)?),
        b"norm" => relief_map("norm", tokens, folder)?,
        b"bump" => relief_map("bump", tokens, folder)?,
        b"map_Bump" => relief_map("map_Bump", tokens, folder)?,
        b"map_bump" => relief_map("map_bump", tokens, folder)?,
        // Comments, and ambient terms, which have no meaning in a physically based renderer.
        keyword if keyword.starts_with(b"#") || HARMLESS.contains(&keyword) => return Ok(None),
        keyword => Statement::Unsupported(String::from_utf8_lossy(keyword).into_owned()),
    };
    Ok(Some(statement))
}

/// A relief statement: `norm`, or one of the spellings of a bump map.
fn relief_map(keyword: &'static str, tokens: Tokens, folder: &Path) -> Result<Statement, String> {
    Ok(Statement::ReliefMap(texture_map(keyword, tokens, folder)?, keyword))
}

fn material_name(tokens: Tokens) -> Option<String> {
    let name = tokens.remainder();
    (!name.is_empty()).then(|| name.into_owned())
}

/// `r g b`, or a single value for grey, as the MTL format allows. Its other two forms, a CIE XYZ
/// colour (`xyz x y z`) and a spectral curve from a file (`spectral file.rfl`), are named in the
/// warning: a reader meets them rarely enough that "malformed number" would mislead.
fn color(tokens: Tokens) -> Result<Vec3, String> {
    if let Some(form @ (b"xyz" | b"spectral")) = tokens.clone().next() {
        return Err(format!("the {} form of a colour is not supported (only r g b)", quote(form)));
    }
    let values = tokens.map(finite_f32).collect::<Result<Vec<_>, _>>()?;
    match values[..] {
        [grey] => Ok(Vec3::splat(grey)),
        [r, g, b] => Ok(Vec3::new(r, g, b)),
        _ => Err(format!("expected 1 or 3 numbers, found {}", values.len())),
    }
}

/// An emitted radiance: a colour none of whose components is negative (light cannot be taken
/// away; a negative weight would also leave the scene without power-proportional light choice).
fn emission(tokens: Tokens) -> Result<Vec3, String> {
    let ke = color(tokens)?;
    if ke.min_element() < 0.0 {
        return Err(format!("Ke must not be negative, found {} {} {}", ke.x, ke.y, ke.z));
    }
    Ok(ke)
}

fn scalar<'a>(mut tokens: impl Iterator<Item = &'a [u8]>) -> Result<f32, String> {
    match (tokens.next(), tokens.next()) {
        (Some(token), None) => finite_f32(token),
        _ => Err("expected exactly one number".to_string()),
    }
}

/// An illumination model: a whole number, or a number written with a fraction (`illum 2.0`),
/// which some exporters write and readers cut to its whole part (Blender: "some MTL files
/// incorrectly use a float for this value"; tinyobjloader reads it with `atoi`).
fn illumination<'a>(mut tokens: impl Iterator<Item = &'a [u8]>) -> Result<u32, String> {
    match (tokens.next(), tokens.next()) {
        (Some(token), None) => {
            let text = std::str::from_utf8(token).ok();
            let whole = text.and_then(|text| text.parse().ok());
            // `as` saturates, so the range test is on the float.
            let cut = || text?.parse::<f32>().ok().filter(|x| (0.0..=u32::MAX as f32).contains(x)).map(|x| x as u32);
            whole.or_else(cut).ok_or_else(|| format!("malformed illumination model {}", quote(token)))
        }
        _ => Err("expected exactly one number".to_string()),
    }
}

/// A texture statement: the file, where it lies on the surface, the channel a scalar map reads
/// (`-imfchan`), a relief map's strength (`-bm`), and the options written before it that lumiere
/// ignores.
struct TextureMap {
    path: PathBuf,
    transform: UvTransform,
    channel: Channel,
    bump_multiplier: f32,
    options: Vec<String>,
}

impl TextureMap {
    /// The map as a material parameter (`map_Pm`, `map_Pr`): its value replaces the constant, as
    /// `map_Kd` replaces `Kd`.
    fn into_parameter(self) -> ParameterMap {
        ParameterMap { path: self.path, transform: self.transform, channel: self.channel, scale: 1.0 }
    }

    /// The map as a material's normal map, given by statement `keyword`: `norm` gives directions,
    /// the bump maps heights, both as strong as `-bm` says.
    fn into_relief(self, keyword: &str) -> NormalMap {
        let relief = if keyword == "norm" { Relief::Directions } else { Relief::Heights { channel: self.channel } };
        NormalMap { path: self.path, transform: self.transform, scale: self.bump_multiplier, relief }
    }
}

/// Whether texture statement `keyword` paints a scalar, whose channel `-imfchan` chooses.
fn is_scalar_map(keyword: &str) -> bool {
    matches!(keyword, "map_Pm" | "map_Pr") || is_bump_map(keyword)
}

/// Whether texture statement `keyword` is a height map.
fn is_bump_map(keyword: &str) -> bool {
    matches!(keyword, "bump" | "map_Bump" | "map_bump")
}

/// The channel `-imfchan VALUE` chooses, among those lumiere reads: `r`, `g`, `b`, or `l` (the
/// luminance, the specification's default for scalar maps).
fn channel(value: &[u8]) -> Option<Channel> {
    match value.to_ascii_lowercase()[..] {
        [b'r'] => Some(Channel::Red),
        [b'g'] => Some(Channel::Green),
        [b'b'] => Some(Channel::Blue),
        [b'l'] => Some(Channel::Luminance),
        _ => None,
    }
}

/// How many values a texture option takes, at least and at most (the MTL specification): `-s`,
/// `-o` and `-t` take one to three numbers (u, then optional v and w), `-mm` two, the others one.
/// `None` for an option the specification does not have.
fn option_values(option: &[u8]) -> Option<(usize, usize)> {
    match option {
        b"-s" | b"-o" | b"-t" => Some((1, 3)),
        b"-mm" => Some((2, 2)),
        b"-blendu" | b"-blendv" | b"-bm" | b"-boost" | b"-cc" | b"-clamp" | b"-imfchan" | b"-texres" | b"-type" => {
            Some((1, 1))
        }
        _ => None,
    }
}

/// Whether `token` starts an option: a `-` and not a number (`-0.5` is a value).
fn is_option(token: &[u8]) -> bool {
    token.starts_with(b"-") && token.len() > 1 && finite_f32(token).is_err()
}

/// Whether `token` is a number for Rust's parser, finite or not.
fn parses_as_f32(token: &[u8]) -> bool {
    std::str::from_utf8(token).is_ok_and(|text| text.parse::<f32>().is_ok())
}

/// Options whose value is what lumiere does anyway: repeat wrapping (`-clamp off`), blending and
/// no colour correction (`-blendu on`, `-blendv on`, `-cc off`). They cost no warning.
fn asks_for_the_default(option: &[u8], values: &[&[u8]]) -> bool {
    let [value] = values else { return false };
    let default: &[u8] = match option {
        b"-clamp" | b"-cc" => b"off",
        b"-blendu" | b"-blendv" => b"on",
        _ => return false,
    };
    value.eq_ignore_ascii_case(default)
}

/// Parses `[options] file`: options come first, each a token that starts with `-` and is not a
/// number, with its values; the rest of the line, spaces included, is the file (Blender writes
/// names with spaces unquoted). `-s` and `-o` place the texture (their u and v; w is for 3D
/// textures); `-imfchan r|g|b|l` chooses a scalar map's channel; `-bm` scales a relief map (`norm`
/// and the bump maps); `-clamp off` is the default,
/// repeat wrapping; the others are returned to be warned about. Backslashes become slashes, since
/// files exported on Windows use them as separators.
fn texture_map(keyword: &str, mut tokens: Tokens, folder: &Path) -> Result<TextureMap, String> {
    let mut transform = UvTransform::default();
    let mut channel_read = Channel::Luminance;
    let mut bump_multiplier = 1.0;
    let mut options = Vec::new();
    loop {
        let mut ahead = tokens.clone();
        let Some(option) = ahead.next().filter(|t| is_option(t)) else { break };
        let arity = option_values(option);
        // The last token is the file, even one whose name starts with `-`.
        if arity.is_none() && ahead.clone().next().is_none() {
            break;
        }
        tokens = ahead;
        let values = take_values(keyword, option, arity, &mut tokens)?;
        // The values of `-s` and `-o` are finite numbers (`take_values`).
        let number = |k: usize, default: f32| values.get(k).and_then(|v| finite_f32(v).ok()).unwrap_or(default);
        if let (b"-imfchan", [value]) = (option, &values[..])
            && is_scalar_map(keyword)
            && let Some(chosen) = channel(value)
        {
            channel_read = chosen;
            continue;
        }
        match option {
            b"-bm" if keyword == "norm" || is_bump_map(keyword) => bump_multiplier = number(0, 1.0),
            b"-s" => transform.scale = glam::Vec2::new(number(0, 1.0), number(1, 1.0)),
            b"-o" => transform.offset = glam::Vec2::new(number(0, 0.0), number(1, 0.0)),
            _ if asks_for_the_default(option, &values) => {}
            _ => options.push(String::from_utf8_lossy(option).into_owned()),
        }
    }
    let file = tokens.remainder_bytes();
    if file.is_empty() {
        return Err(format!("{keyword} without a file name"));
    }
    let file: Vec<u8> = file.iter().map(|&b| if b == b'\\' { b'/' } else { b }).collect();
    let path = folder.join(path_from_bytes(file));
    Ok(TextureMap { path, transform, channel: channel_read, bump_multiplier, options })
}

/// Takes the values of texture option `option` (with `arity`, from [`option_values`]) off
/// `tokens`: as many as it takes, numbers where they must be; an option unknown to the
/// specification takes the numbers that follow it.
fn take_values<'a>(
    keyword: &str,
    option: &[u8],
    arity: Option<(usize, usize)>,
    tokens: &mut Tokens<'a>,
) -> Result<Vec<&'a [u8]>, String> {
    let numeric = !matches!(option, b"-blendu" | b"-blendv" | b"-cc" | b"-clamp" | b"-imfchan" | b"-type");
    let (least, most) = arity.unwrap_or((0, usize::MAX));
    let mut values = Vec::new();
    while values.len() < most {
        let mut ahead = tokens.clone();
        match ahead.next() {
            Some(value) if !numeric || finite_f32(value).is_ok() => values.push(value),
            _ => break,
        }
        *tokens = ahead;
    }
    if arity.is_none() {
        // Its values are not options lumiere reads: only skipped.
        return Ok(Vec::new());
    }
    if values.len() < least {
        // Name a value that is there but not finite (`-s 1e39`, `-o nan`); another word is the
        // file, after too few values.
        let problem = match tokens.clone().next() {
            Some(token) if numeric && parses_as_f32(token) => finite_f32(token).err(),
            _ => None,
        };
        let problem = problem.unwrap_or_else(|| format!("expected {least} value(s), found {}", values.len()));
        return Err(format!("{keyword} {}: {problem}", quote(option)));
    }
    Ok(values)
}
