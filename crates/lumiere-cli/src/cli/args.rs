use std::path::PathBuf;

use clap::{Args, Parser, Subcommand, ValueEnum};
use glam::Vec3;

#[derive(Parser, Debug)]
#[command(name = "lumiere", version, about = "A CPU Monte Carlo ray tracer", propagate_version = true)]
pub struct Cli {
    #[command(subcommand)]
    pub command: Command,
}

#[derive(Subcommand, Debug)]
pub enum Command {
    /// Render a scene (gKit's Cornell box when no scene is given) to an image.
    Render(RenderArgs),
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
    #[arg(long, value_parser = parse_size, default_value = "256x192")]
    pub size: (u32, u32),

    /// Samples of the converged reference image.
    #[arg(long, default_value_t = 8192)]
    pub reference_samples: u32,

    /// Seeds averaged per measurement.
    #[arg(long, default_value_t = 4)]
    pub seeds: u64,
}

#[derive(Args, Debug)]
pub struct BenchLabArgs {
    /// Timed renders per row; the median is reported.
    #[arg(long, default_value_t = 3)]
    pub repeats: usize,

    /// A reduced run for CI: 256x192, one render per row.
    #[arg(long)]
    pub quick: bool,

    /// Also write the table as JSON to this file.
    #[arg(long)]
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

    /// Thread counts to measure, comma-separated.
    #[arg(long, value_delimiter = ',', default_value = "1,2")]
    pub threads: Vec<usize>,

    /// Timed repetitions per measurement; the median is reported.
    #[arg(long, default_value_t = 5)]
    pub repeats: usize,

    /// Seed of the shadow and diffuse rays.
    #[arg(long, default_value_t = 0)]
    pub seed: u64,

    /// Also write the results as JSON to this file.
    #[arg(long)]
    pub json: Option<PathBuf>,

    /// Write each scene's triangles and ray sets (binary, see bench/README.md) under this folder,
    /// for bench/embree_compare.py.
    #[arg(long)]
    pub export_rays: Option<PathBuf>,
}

#[derive(Args, Debug)]
pub struct InfoArgs {
    /// Wavefront OBJ file (.obj or .obj.gz) with its MTL files.
    pub scene: PathBuf,
}

#[derive(Clone, Copy, Debug, PartialEq, Eq, ValueEnum)]
pub enum ModeArg {
    /// White where a camera ray hits a triangle, black elsewhere.
    Hits,
    /// Diffuse colour (Kd) of the hit triangle.
    Materials,
    /// Hard shadows: one shadow ray to each light triangle's centroid.
    Shadows,
    /// Soft shadows: direct light integrated over the area lights with --samples points.
    Direct,
    /// Ambient occlusion: fraction of --samples cosine-weighted directions that see the sky.
    Ao,
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
    /// Wavefront OBJ file (.obj or .obj.gz); the built-in gKit Cornell box when omitted.
    pub scene: Option<PathBuf>,

    /// What to compute per pixel.
    #[arg(long, value_enum, default_value_t = ModeArg::Shadows)]
    pub mode: ModeArg,

    /// Samples per light triangle (direct), in total (direct with power light sampling) or per
    /// hemisphere (ao).
    #[arg(long, default_value_t = 16, value_parser = clap::value_parser!(u32).range(1..))]
    pub samples: u32,

    /// Camera samples per pixel; 1 is one ray through the pixel centre, more are jittered in the pixel.
    #[arg(long, default_value_t = 1)]
    pub spp: u32,

    /// Random number generator for the Monte Carlo modes.
    #[arg(long, value_enum, default_value_t = SamplerArg::Independent)]
    pub sampler: SamplerArg,

    /// How direct lighting chooses its light samples.
    #[arg(long, value_enum, default_value_t = LightSamplingArg::PerLight)]
    pub light_sampling: LightSamplingArg,

    /// Ambient occlusion rays stop at this distance (default: infinite, visibility of the sky).
    #[arg(long)]
    pub ao_distance: Option<f32>,

    /// Set the emission Ke of a material, NAME=r,g,b (repeatable); e.g. Emission=5,5,5 on the staircase.
    #[arg(long, value_parser = parse_emission)]
    pub emission: Vec<(String, Vec3)>,

    /// Image size, WIDTHxHEIGHT.
    #[arg(long, value_parser = parse_size, default_value = "1024x768")]
    pub size: (u32, u32),

    /// gKit orbiter camera file (c, p, r, s, optional f lines); the built-in scene uses gKit's 2022 one.
    #[arg(long, conflicts_with_all = ["eye", "target"])]
    pub orbiter: Option<PathBuf>,

    /// Look-at camera position, x,y,z (needs --target). Without a camera, the view frames the scene.
    #[arg(long, value_parser = parse_vec3, requires = "target", allow_hyphen_values = true)]
    pub eye: Option<Vec3>,

    /// Look-at camera target, x,y,z.
    #[arg(long, value_parser = parse_vec3, requires = "eye", allow_hyphen_values = true)]
    pub target: Option<Vec3>,

    /// Look-at camera up direction, x,y,z.
    #[arg(long, value_parser = parse_vec3, default_value = "0,1,0", allow_hyphen_values = true)]
    pub up: Vec3,

    /// Vertical field of view of the look-at camera, degrees.
    #[arg(long, default_value_t = 45.0)]
    pub fov: f32,

    /// Worker threads; 0 = one per core, 1 = serial.
    #[arg(long, default_value_t = 0)]
    pub threads: usize,

    /// Seed of the random numbers; the same seed gives the same image bytes for any thread count.
    #[arg(long, default_value_t = 0)]
    pub seed: u64,

    /// Output image: .png (8-bit sRGB), .exr or .pfm (linear float).
    #[arg(short, long, default_value = "render.png")]
    pub output: PathBuf,

    /// Write PNGs as gKit does (floor(255*c), no gamma) for side-by-side comparison with gKit renders.
    #[arg(long)]
    pub png_linear: bool,

    /// Write render statistics (mode, size, rays, timings) as JSON to this file.
    #[arg(long)]
    pub stats_json: Option<PathBuf>,

    /// Stop after the pass that crosses this rendering time (e.g. 30s, 5m, 1h, 1.5s).
    #[arg(long, value_parser = parse_duration)]
    pub time: Option<std::time::Duration>,

    /// Stop once the estimated relative standard error of the image is below this (e.g. 0.01).
    #[arg(long)]
    pub noise: Option<f64>,

    /// Rewrite the output image with the current estimate every SECONDS (atomically).
    #[arg(long)]
    pub preview_every: Option<f64>,

    /// Save the accumulation state to this file after passes (atomically), for --resume.
    #[arg(long)]
    pub checkpoint: Option<PathBuf>,

    /// Seconds between checkpoints; 0 saves after every pass.
    #[arg(long, default_value_t = 0.0)]
    pub checkpoint_every: f64,

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
    let s = s.trim();
    let (number, unit) = s.split_at(s.find(|c: char| c.is_ascii_alphabetic()).unwrap_or(s.len()));
    let value: f64 = number.trim().parse().map_err(|_| format!("expected a duration like 30s, 5m or 1h, got '{s}'"))?;
    let seconds = match unit {
        "" | "s" => value,
        "ms" => value / 1e3,
        "m" | "min" => value * 60.0,
        "h" => value * 3600.0,
        _ => return Err(format!("unknown time unit '{unit}' (use ms, s, m or h)")),
    };
    std::time::Duration::try_from_secs_f64(seconds).map_err(|_| format!("'{s}' is not a valid duration"))
}

fn parse_emission(s: &str) -> Result<(String, Vec3), String> {
    let (name, value) = s.split_once('=').ok_or_else(|| format!("expected NAME=r,g,b, got '{s}'"))?;
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
