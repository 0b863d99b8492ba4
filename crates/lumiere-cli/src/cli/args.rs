use std::path::PathBuf;

use clap::{Args, Parser, Subcommand, ValueEnum};
use glam::Vec3;
use lumiere::accel::Isa;
use lumiere::image_io::PngStyle;
use lumiere::render::aov::Aov;
use lumiere::util::threads::MAX_THREADS;

#[derive(Parser, Debug)]
#[command(name = "lumiere", version = concat!(env!("CARGO_PKG_VERSION"), " (", env!("LUMIERE_COMMIT"), ")"), about = "A CPU Monte Carlo ray tracer", propagate_version = true)]
pub struct Cli {
    #[command(subcommand)]
    pub command: Command,
}

#[derive(Subcommand, Debug)]
pub enum Command {
    /// Render a scene (gKit's Cornell box when no scene is given) to an image.
    Render(Box<RenderArgs>),
    /// Print a scene's triangles, materials, lights, bounds and load time.
    Info(InfoArgs),
    /// Measure BVH build and traversal on the benchmark scenes (Markdown tables on stdout).
    BenchBvh(BenchBvhArgs),
    /// Reproduce the lab's timing table on the built-in scene, serial and parallel (Markdown on stdout).
    Bench(BenchLabArgs),
    /// Compare the samplers' image error against a converged reference (Markdown on stdout).
    BenchSampler(BenchSamplerArgs),
}

#[derive(Args, Debug)]
pub struct BenchSamplerArgs {
    /// Image size, WIDTHxHEIGHT.
    #[arg(long, value_parser = parse_size, default_value = "256x192", allow_hyphen_values = true)]
    pub size: (u32, u32),

    /// Samples of the converged reference image (1 to 65536).
    #[arg(long, default_value_t = 8192, value_parser = parse_reference_samples)]
    pub reference_samples: u32,

    /// Seeds averaged per measurement (1 to 1000).
    #[arg(long, default_value_t = 4, value_parser = parse_seeds, allow_hyphen_values = true)]
    pub seeds: u64,
}

#[derive(Args, Debug)]
pub struct BenchLabArgs {
    /// Timed renders per row (1 to 1000); the median is reported.
    #[arg(long, default_value_t = 3, value_parser = parse_repeats)]
    pub repeats: usize,

    /// A reduced run for CI: 256x192, one render per row.
    #[arg(long)]
    pub quick: bool,

    /// SIMD kernels of the BVH: avx512, avx2, sse2 or portable (default: the widest this CPU
    /// has, or $LUMIERE_ISA). Every ISA gives the same image bytes.
    #[arg(long, value_parser = parse_isa)]
    pub isa: Option<Isa>,

    /// Also write the table as JSON to this file.
    #[arg(long, value_parser = parse_json_path)]
    pub json: Option<PathBuf>,
}

#[derive(Args, Debug)]
pub struct BenchBvhArgs {
    /// Comma-separated benchmark scenes: cornell (built in), bunny, bunny-1m, staircase.
    #[arg(long, default_value = "cornell,bunny,bunny-1m,staircase")]
    pub scenes: String,

    /// Folder holding the test scenes (bunny/, bunny-1m/, staircase/).
    #[arg(long, default_value = "../shared/scenes")]
    pub scenes_dir: PathBuf,

    /// Thread counts to measure, comma-separated (each at most 1024; 0 = RAYON_NUM_THREADS if set, else one per core).
    #[arg(long, value_delimiter = ',', default_value = "1,2", value_parser = parse_threads, allow_hyphen_values = true)]
    pub threads: Vec<usize>,

    /// SIMD kernels of the BVH: avx512, avx2, sse2 or portable (default: the widest this CPU
    /// has, or $LUMIERE_ISA). Every ISA gives the same image bytes.
    #[arg(long, value_parser = parse_isa)]
    pub isa: Option<Isa>,

    /// Timed repetitions per measurement (1 to 1000); the median is reported.
    #[arg(long, default_value_t = 5, value_parser = parse_repeats)]
    pub repeats: usize,

    /// Seed of the shadow and diffuse rays.
    #[arg(long, default_value_t = 0, allow_hyphen_values = true)]
    pub seed: u64,

    /// Also write the results as JSON to this file.
    #[arg(long, value_parser = parse_json_path)]
    pub json: Option<PathBuf>,

    /// Write each scene's triangles and ray sets (binary, see bench/README.md) under this folder
    /// (made if missing), each scene's as a folder that replaces the last one whole, for
    /// bench/embree_compare.py.
    #[arg(long)]
    pub export_rays: Option<PathBuf>,
}

#[derive(Args, Debug)]
pub struct InfoArgs {
    /// Scene file: Wavefront OBJ (.obj) with its MTL files, glTF 2.0 (.gltf with its buffers and
    /// images, or .glb) or PLY (.ply), each also gzipped (.obj.gz, ...); the built-in scene when
    /// omitted.
    pub scene: Option<PathBuf>,
}

#[derive(Clone, Copy, Debug, PartialEq, Eq, ValueEnum)]
pub enum ModeArg {
    /// White where a camera ray hits a triangle, black elsewhere.
    Hits,
    /// Colour of the hit surface: its albedo, texture included (Kd for the lab's diffuse scenes).
    Materials,
    /// Hard shadows: one shadow ray to each light triangle's centroid.
    Shadows,
    /// Soft shadows: direct light integrated over the area lights with --samples points.
    Direct,
    /// Ambient occlusion: fraction of --samples cosine-weighted directions that see the sky (a
    /// multiple of 4 is stratified: a quarter of them in each quarter turn about the normal).
    Ao,
    /// Global illumination: path tracing with next-event estimation and MIS (see --max-depth).
    Path,
}

#[derive(Clone, Copy, Debug, PartialEq, Eq, ValueEnum)]
pub enum TonemapArg {
    /// Clip each channel at 1.
    Clamp,
    /// Narkowicz's fit of the ACES filmic curve: highlights roll off instead of clipping.
    Aces,
}

#[derive(Clone, Copy, Debug, PartialEq, Eq, ValueEnum)]
pub enum SamplerArg {
    /// Hashed independent random numbers.
    Independent,
    /// Owen-scrambled Sobol points: lower error for the same sample count.
    Sobol,
}

#[derive(Clone, Copy, Debug, PartialEq, Eq, ValueEnum)]
pub enum LightSamplingArg {
    /// --samples points on every light triangle (the lab's count).
    PerLight,
    /// --samples points in total, lights chosen in proportion to their power.
    Power,
}

#[derive(Args, Debug)]
pub struct RenderArgs {
    /// Scene file: Wavefront OBJ (.obj) with its MTL files, glTF 2.0 (.gltf with its buffers and
    /// images, or .glb) or PLY (.ply), each also gzipped (.obj.gz, ...); the built-in gKit Cornell
    /// box when omitted.
    pub scene: Option<PathBuf>,

    /// What to compute per pixel: path tracing, or one of the lab's steps.
    #[arg(long, value_enum, default_value_t = ModeArg::Path)]
    pub mode: ModeArg,

    /// Longest path in segments from the camera, as Mitsuba counts (path only): 1 shows the
    /// emitters, 2 direct light, 8 up to seven bounces; 0 = no limit (Russian roulette ends paths).
    /// [default: 8]
    #[arg(long, allow_hyphen_values = true)]
    pub max_depth: Option<u32>,

    /// Samples per camera sample, for direct and ao only: points on every light triangle (direct),
    /// points in total (direct with --light-sampling power), or directions (ao). A pixel traces
    /// samples x spp rays. [default: 16]
    #[arg(long, value_parser = clap::value_parser!(u32).range(1..), allow_hyphen_values = true)]
    pub samples: Option<u32>,

    /// Camera samples per pixel, each a pass over the image: 1 is one ray through each pixel centre
    /// (the lab's images), more are jittered in the pixel. [default: 8 for path, 1 for the lab's
    /// modes, or unlimited with --time or --noise: the render goes on until the budget is met]
    // 2^32 - 1 is the library's "until a budget stops it" (`RenderOptions::spp`), which leaving
    // --spp out asks for; as a number it would render without end.
    #[arg(long, value_parser = clap::value_parser!(u32).range(1..=i64::from(u32::MAX - 1)), allow_hyphen_values = true)]
    pub spp: Option<u32>,

    /// Random number generator for the Monte Carlo modes. [default: sobol for path (about half
    /// the error of independent at 64 spp on the Cornell box), independent for the lab's modes]
    #[arg(long, value_enum)]
    pub sampler: Option<SamplerArg>,

    /// How direct lighting chooses its light samples.
    /// [default: per-light; direct only]
    #[arg(long, value_enum)]
    pub light_sampling: Option<LightSamplingArg>,

    /// Ambient occlusion rays stop at this distance (default: infinite, visibility of the sky; ao only).
    #[arg(long, value_parser = parse_positive_f32, allow_hyphen_values = true)]
    pub ao_distance: Option<f32>,

    /// Set the emission Ke of a material, NAME=r,g,b (repeatable); e.g. Emission=5,5,5 on the staircase.
    #[arg(long, value_parser = parse_emission)]
    pub emission: Vec<(String, Vec3)>,

    /// Image size, WIDTHxHEIGHT.
    #[arg(long, value_parser = parse_size, default_value = "1024x768", allow_hyphen_values = true)]
    pub size: (u32, u32),

    /// gKit orbiter camera file (c, p, r, s, optional f lines); the built-in scene uses gKit's 2022 one.
    #[arg(long, conflicts_with_all = ["eye", "target"])]
    pub orbiter: Option<PathBuf>,

    /// Look-at camera position, x,y,z (needs --target). Without a camera, a glTF scene is seen from
    /// its first perspective camera, if it has one; otherwise the view frames the scene.
    #[arg(long, value_parser = parse_vec3, requires = "target", allow_hyphen_values = true)]
    pub eye: Option<Vec3>,

    /// Look-at camera target, x,y,z.
    #[arg(long, value_parser = parse_vec3, requires = "eye", allow_hyphen_values = true)]
    pub target: Option<Vec3>,

    /// Look-at camera up direction, x,y,z (also for the view that frames a scene, and in place of a
    /// glTF camera's). [default: 0,1,0]
    #[arg(long, value_parser = parse_vec3, allow_hyphen_values = true)]
    pub up: Option<Vec3>,

    /// Vertical field of view of the look-at camera, in degrees, between 0 and 180 (exclusive);
    /// orbiter cameras use gKit's 45. [default: 45, or a glTF camera's own]
    #[arg(long, value_parser = parse_fov, allow_hyphen_values = true)]
    pub fov: Option<f32>,

    /// SIMD kernels of the BVH: avx512, avx2, sse2 or portable (default: the widest this CPU
    /// has, or $LUMIERE_ISA). Every ISA gives the same image bytes.
    #[arg(long, value_parser = parse_isa)]
    pub isa: Option<Isa>,

    /// Worker threads, at most 1024; 0 = RAYON_NUM_THREADS if set, else one per core; 1 = serial.
    #[arg(long, default_value_t = 0, value_parser = parse_threads, allow_hyphen_values = true)]
    pub threads: usize,

    /// Seed of the random numbers; the same seed gives the same image bytes for any thread count.
    #[arg(long, default_value_t = 0, allow_hyphen_values = true)]
    pub seed: u64,

    /// Output image: .png (8-bit sRGB), .exr or .pfm (linear float).
    #[arg(short, long, default_value = "render.png")]
    pub output: PathBuf,

    /// Write PNGs as gKit does (clamped, floor(255*c), no gamma) for side-by-side comparison with gKit renders; --tonemap aces still applies the curve first.
    #[arg(long)]
    pub png_linear: bool,

    /// Exposure of the PNG in stops: each +1 doubles the brightness (EXR and PFM stay linear). [default: 0]
    #[arg(long, value_parser = parse_exposure, allow_hyphen_values = true)]
    pub exposure: Option<f32>,

    /// How the PNG maps radiance to the display: clamp (clip at 1, the lab's images) or aces (a
    /// filmic curve). [default: aces for path, clamp for the lab's modes and with --png-linear]
    #[arg(long, value_enum)]
    pub tonemap: Option<TonemapArg>,

    /// Extra EXR channels beside the image, comma-separated: albedo (first-hit colour, as denoisers
    /// want), normal (first-hit shading normal), depth (distance to the first hit). Needs -o *.exr.
    #[arg(long, value_delimiter = ',', value_parser = parse_aov)]
    pub aov: Vec<Aov>,

    /// Denoise the image with Intel Open Image Denoise (its RT filter, guided by the albedo and
    /// normal AOVs), loaded at run time: `pip install pyoidn` or set OIDN_DIR. An .exr output keeps
    /// the noisy image as the `noisy` layer.
    #[arg(long)]
    pub denoise: bool,

    /// Write render statistics (mode, size, rays, timings) as JSON to this .json file; `-` for stdout.
    #[arg(long, value_parser = parse_stats_json_path)]
    pub stats_json: Option<PathBuf>,

    /// Stop after this much rendering time in this run, keeping the completed passes (e.g. 30s, 5m, 1h, 1.5s).
    #[arg(long, value_parser = parse_duration, allow_hyphen_values = true)]
    pub time: Option<std::time::Duration>,

    /// Stop once the estimated relative standard error of the image is below this (e.g. 0.01). A
    /// target more than an hour away at the render's rate is said once, early.
    #[arg(long, value_parser = parse_positive_f64, allow_hyphen_values = true)]
    pub noise: Option<f64>,

    /// Rewrite the output image with the current estimate every SECONDS (atomically), between passes.
    #[arg(long, value_parser = parse_positive_f64, allow_hyphen_values = true)]
    pub preview_every: Option<f64>,

    /// Save the accumulation state to this file after passes (atomically), for --resume.
    #[arg(long)]
    pub checkpoint: Option<PathBuf>,

    /// Seconds between checkpoints (with --checkpoint); 0 saves after every pass. [default: 0]
    #[arg(long, value_parser = parse_non_negative_f64, allow_hyphen_values = true)]
    pub checkpoint_every: Option<f64>,

    /// Continue the render saved in this checkpoint (same scene and options; --spp may grow).
    #[arg(long)]
    pub resume: Option<PathBuf>,
}

fn parse_size(s: &str) -> Result<(u32, u32), String> {
    let (w, h) = s.split_once(['x', 'X']).ok_or_else(|| format!("expected WIDTHxHEIGHT, got '{s}'"))?;
    let parse = |v: &str| v.trim().parse::<u32>().map_err(|_| format!("'{v}' is not a positive integer"));
    let (w, h) = (parse(w)?, parse(h)?);
    if w == 0 || h == 0 {
        return Err(format!("image size {w}x{h} has no pixels"));
    }
    Ok((w, h))
}

fn parse_duration(s: &str) -> Result<std::time::Duration, String> {
    let text = s.trim();
    // The unit is a suffix, so that exponents parse: 1e3s, 2.5e-1h.
    let units: [(&str, f64); 5] = [("ms", 1e-3), ("min", 60.0), ("s", 1.0), ("m", 60.0), ("h", 3600.0)];
    let (number, scale) =
        units.iter().find_map(|&(unit, scale)| Some((text.strip_suffix(unit)?, scale))).unwrap_or((text, 1.0));
    let value: f64 = number
        .trim()
        .parse()
        .map_err(|_| format!("expected a duration like 30s, 5m, 1h or 1e3s, got {text:?} (units: ms, s, m, h)"))?;
    if !(value.is_finite() && value > 0.0) {
        return Err(format!("a duration must be positive and finite, got {text:?}"));
    }
    std::time::Duration::try_from_secs_f64(value * scale).map_err(|_| format!("{text:?} is too long a duration"))
}

fn parse_finite(s: &str) -> Result<f64, String> {
    let value: f64 = s.trim().parse().map_err(|_| format!("expected a number, got {s:?}"))?;
    if value.is_finite() { Ok(value) } else { Err(format!("expected a finite number, got {s:?}")) }
}

fn parse_positive_f64(s: &str) -> Result<f64, String> {
    let value = parse_finite(s)?;
    if value > 0.0 { Ok(value) } else { Err(format!("must be positive, got {s:?}")) }
}

fn parse_non_negative_f64(s: &str) -> Result<f64, String> {
    let value = parse_finite(s)?;
    if value >= 0.0 { Ok(value) } else { Err(format!("must not be negative, got {s:?}")) }
}

fn parse_positive_f32(s: &str) -> Result<f32, String> {
    let value = parse_positive_f64(s)? as f32;
    if value.is_finite() && value > 0.0 { Ok(value) } else { Err(format!("out of range, got {s:?}")) }
}

/// A JSON output: a `.json` file, so that a slip (`--json scene.obj`, `--stats-json notes.txt`)
/// cannot replace an input or another file with the table, and a folder is refused before the
/// work runs.
fn parse_json_path(s: &str) -> Result<PathBuf, String> {
    let path = PathBuf::from(s);
    if path.is_dir() {
        return Err(format!("{s:?} is a directory; expected a .json file name"));
    }
    match path.extension() {
        Some(extension) if extension.eq_ignore_ascii_case("json") => Ok(path),
        _ => Err(format!("expected a .json file name, got {s:?}")),
    }
}

/// `--stats-json -` writes the statistics to stdout.
pub const STDOUT_ARG: &str = "-";

/// The render statistics' output: a `.json` file, as for a benchmark's, or `-` for stdout.
fn parse_stats_json_path(s: &str) -> Result<PathBuf, String> {
    if s == STDOUT_ARG { Ok(PathBuf::from(s)) } else { parse_json_path(s) }
}

/// Timed repetitions of a benchmark: at least one, and few enough that their times fit in memory.
fn parse_repeats(s: &str) -> Result<usize, String> {
    match s.trim().parse::<usize>() {
        Ok(value @ 1..=1000) => Ok(value),
        _ => Err(format!("expected a number of repetitions from 1 to 1000, got {s:?}")),
    }
}

/// The reference's samples per pixel (per light triangle, or AO directions): at least one, and
/// few enough that a reference finishes (65536 take hours at the default size).
fn parse_reference_samples(s: &str) -> Result<u32, String> {
    match s.trim().parse::<u32>() {
        Ok(value @ 1..=65536) => Ok(value),
        _ => Err(format!("expected a number of samples from 1 to 65536, got {s:?}")),
    }
}

/// Seeds averaged by `bench-sampler`: at least one (no seed has no error to average).
fn parse_seeds(s: &str) -> Result<u64, String> {
    match s.trim().parse::<u64>() {
        Ok(value @ 1..=1000) => Ok(value),
        _ => Err(format!("expected a number of seeds from 1 to 1000, got {s:?}")),
    }
}

fn parse_aov(s: &str) -> Result<Aov, String> {
    Aov::parse(s.trim()).map_err(|e| e.to_string())
}

fn parse_exposure(s: &str) -> Result<f32, String> {
    let value = parse_finite(s)?;
    let max = PngStyle::MAX_EXPOSURE;
    if value.abs() <= f64::from(max) {
        Ok(value as f32)
    } else {
        Err(format!("an exposure between -{max} and {max} stops, got {s:?}"))
    }
}

fn parse_fov(s: &str) -> Result<f32, String> {
    let value = parse_finite(s)?;
    if value > 0.0 && value < 180.0 && value as f32 > 0.0 && (value as f32) < 180.0 {
        Ok(value as f32)
    } else {
        Err(format!("the field of view must be between 0 and 180 degrees (exclusive), got {s:?}"))
    }
}

fn parse_threads(s: &str) -> Result<usize, String> {
    let value: usize = s.trim().parse().map_err(|_| format!("expected a thread count, got {s:?}"))?;
    if value <= MAX_THREADS { Ok(value) } else { Err(format!("at most {MAX_THREADS} threads, got {value}")) }
}

fn parse_isa(s: &str) -> Result<Isa, String> {
    super::isa::parse(s)
}

fn parse_emission(s: &str) -> Result<(String, Vec3), String> {
    // At the last `=`: a colour never holds one, a material name may (`python -m
    // lumiere.distributed` splits there too).
    let (name, value) = s
        .rsplit_once('=')
        .filter(|(name, _)| !name.is_empty())
        .ok_or_else(|| format!("expected NAME=r,g,b, got '{s}'"))?;
    let ke = parse_vec3(value)?;
    if ke.min_element() < 0.0 {
        return Err(format!("emission must not be negative, got '{value}'"));
    }
    Ok((name.to_string(), ke))
}

fn parse_vec3(s: &str) -> Result<Vec3, String> {
    let values: Vec<f32> = s
        .split(',')
        .map(|v| v.trim().parse::<f32>().ok().filter(|f| f.is_finite()))
        .collect::<Option<_>>()
        .ok_or_else(|| format!("expected three finite numbers x,y,z, got '{s}'"))?;
    match values[..] {
        [x, y, z] => Ok(Vec3::new(x, y, z)),
        _ => Err(format!("expected three numbers x,y,z, got '{s}'")),
    }
}
