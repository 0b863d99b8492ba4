//! A scene with everything derived from it once before rendering: the acceleration structure and
//! the lights. Integrators see the scene only through a [`World`].

use std::sync::OnceLock;

use glam::{Vec2, Vec3};

use crate::accel::simd::lanes_of;
use crate::accel::{Accel, BuildPreset, Hit, Isa, OriginBatch, Region};
use crate::geometry::surface::SurfacePoint;
use crate::geometry::surface_lanes::{HitCorners, SurfaceRows};
use crate::lights::LightSet;
use crate::materials::{CoverageTest, Material, MaterialBsdf, MaterialKind};
use crate::math::rows::{Rows, row, set_row};
use crate::math::{Ray, UvTransform};
use crate::scene::Scene;
use crate::scene::mesh::NO_INDEX;
use crate::textures::{TextureId, TextureSet};
use crate::util::hash::mix64;
use crate::util::memory::prefetch;
use normals::{Corners, NormalMaps};
use parameters::ParameterTextures;

mod normals;
mod parameters;

pub struct World {
    scene: Scene,
    /// The wide BVH of the ISA chosen; the binary tree it was collapsed from is dropped to save memory.
    accel: Accel,
    lights: LightSet,
    /// Each material's kind, mapped once from its statements.
    kinds: Vec<MaterialKind>,
    /// Each material's diffuse texture, decoded once.
    texture_of_material: Vec<Option<BaseColourMap>>,
    textures: TextureSet,
    /// The textures that paint materials' metallic weight and roughness, which make a PBR
    /// material's kind vary over its surface.
    parameters: ParameterTextures,
    /// The normal maps that bend materials' shading normals.
    normal_maps: NormalMaps,
    /// How each material's surface is cut out, if it is: rays pass through it where its coverage
    /// fails the material's test ([`World::opaque_at`]).
    cutout_of_material: Vec<Option<Cutout>>,
    /// The coverage textures (`map_d`) that decoded, each once.
    cutouts: TextureSet,
    /// Whether a material may be cut out; without one (most scenes) every query goes straight to
    /// the BVH, its packets and batches (see [`World::has_cutouts`]).
    cuts: bool,
    /// What could not be derived (textures that failed to load), for the user to see.
    warnings: Vec<String>,
    /// The diagonal of the scene's bounding box: no two of its points lie farther apart.
    diameter: f32,
    /// For each light, the triangles that may block a segment ending at its hard-shadow target
    /// ([`World::hard_shadow_batch`]), gathered when first asked for (only hard shadows ask);
    /// empty where no light's would be gathered.
    hard_shadow_batches: OnceLock<Vec<OriginBatch>>,
    /// Whether the records shading reads (the mesh's, the textures') outgrow a core's caches, so
    /// that asking for them ahead ([`World::prefetch_hit`], [`World::prefetch_bsdf`]) pays:
    /// where they all stay cached (the Cornell box), the requests only cost.
    prefetches: bool,
}

/// Each light's [`World::hard_shadow_batch`], or none if no light's candidates were gathered.
fn hard_shadow_batches(accel: &Accel, lights: &LightSet) -> Vec<OriginBatch> {
    let batches: Vec<OriginBatch> = lights
        .lights()
        .iter()
        .map(|light| {
            let target = light.hard_shadow_target();
            // Split into quarters (as ambient occlusion does), the box's were tested against about
            // half as many triangles each, but the render took as long.
            let region = Region::hemisphere(target, light.normal);
            let mut batch = OriginBatch::default();
            accel.prepare_batch(&mut batch, target, &region, u32::MAX);
            batch
        })
        .collect();
    if batches.iter().all(OriginBatch::traverses) { Vec::new() } else { batches }
}

/// The shading data above which [`World::prefetch_hit`] and [`World::prefetch_bsdf`] ask for
/// anything: about a core's second-level cache.
const PREFETCH_ABOVE_BYTES: usize = 1 << 20;

impl World {
    /// Builds the BVH over the scene's triangles for the widest instruction set this CPU has,
    /// derives its lights and the kind of each material, and decodes its textures.
    pub fn new(scene: Scene, preset: BuildPreset) -> World {
        World::with_isa(scene, preset, Isa::detect())
    }

    /// As [`World::new`], with the BVH of `isa` (every ISA gives the same image bytes).
    ///
    /// # Panics
    /// If this CPU cannot run `isa` ([`Isa::is_supported`]).
    pub fn with_isa(scene: Scene, preset: BuildPreset, isa: Isa) -> World {
        let accel = Accel::build(&scene.mesh.positions, &scene.mesh.indices, preset, isa);
        let lights = LightSet::new(&scene);
        let kinds = scene.materials.iter().map(Material::kind).collect();
        let (texture_of_material, textures, mut warnings) =
            TextureSet::for_materials(scene.materials.iter().map(|m| m.map_kd.as_deref()), &scene.embedded_images);
        let texture_of_material = BaseColourMap::of_materials(texture_of_material, &scene.materials);
        let (parameters, parameter_warnings) =
            ParameterTextures::for_materials(&scene.materials, &scene.embedded_images);
        warnings.extend(parameter_warnings);
        let (normal_maps, normal_warnings) = NormalMaps::for_materials(&scene.materials, &scene.embedded_images);
        warnings.extend(normal_warnings);
        warnings.extend(scene.materials.iter().filter_map(Material::ignored_mask_warning));
        let (cutout_of_material, cutouts, cutout_warnings) =
            TextureSet::for_cutouts(scene.materials.iter().map(Material::cutout_mask), &scene.embedded_images);
        warnings.extend(cutout_warnings);
        let textures_of_cutouts = placed(cutout_of_material, scene.materials.iter().map(|m| m.map_d_transform));
        let cutout_of_material: Vec<Option<Cutout>> = scene
            .materials
            .iter()
            .zip(textures_of_cutouts)
            .map(|(material, texture)| cutout(material, texture))
            .collect();
        let cuts = cutout_of_material.iter().flatten().any(|cutout| cutout.may_cut(&cutouts));
        let diameter = scene.bounds().extent().length();
        let texture_bytes = textures.memory_bytes() + parameters.memory_bytes() + normal_maps.memory_bytes();
        let prefetches = scene.mesh.memory_bytes() + texture_bytes > PREFETCH_ABOVE_BYTES;
        World {
            scene,
            accel,
            lights,
            kinds,
            texture_of_material,
            textures,
            parameters,
            normal_maps,
            cutout_of_material,
            cutouts,
            cuts,
            warnings,
            diameter,
            hard_shadow_batches: OnceLock::new(),
            prefetches,
        }
    }

    /// The candidate triangles of the segments that end at light `light`'s hard-shadow target
    /// ([`crate::lights::AreaLight::hard_shadow_target`]), read backwards as rays leaving it
    /// into the half-space in front of the light: every such segment of an image leaves from that
    /// one point, so the batch is gathered once for the whole render, not once per receiver.
    /// `None` where the candidates were not gathered (a large scene, cutouts: see
    /// [`OriginBatch::prepare`]).
    #[inline]
    pub fn hard_shadow_batch(&self, light: usize) -> Option<&OriginBatch> {
        let batches = self.hard_shadow_batches.get_or_init(|| {
            // A batch's triangles know nothing of cutouts.
            if self.has_cutouts() { Vec::new() } else { hard_shadow_batches(&self.accel, &self.lights) }
        });
        batches.get(light).filter(|batch| !batch.traverses())
    }

    pub fn scene(&self) -> &Scene {
        &self.scene
    }

    pub fn accel(&self) -> &Accel {
        &self.accel
    }

    pub fn lights(&self) -> &LightSet {
        &self.lights
    }

    /// The diagonal of the scene's bounding box: no ray leaving a point of the scene meets
    /// anything farther than this.
    pub fn diameter(&self) -> f32 {
        self.diameter
    }

    /// The stable hashes of the files material `material`'s diffuse, coverage, metallic,
    /// roughness and normal textures were decoded from, `None` where it has none or its file
    /// could not be used.
    pub fn texture_contents(&self, material: usize) -> [Option<u64>; 5] {
        let cutout = self.cutout_of_material[material].and_then(|cutout| cutout.texture);
        let diffuse = self.texture_of_material[material].map(|map| self.textures.contents_hash(map.texture));
        let coverage = cutout.map(|(id, _)| self.cutouts.contents_hash(id));
        let [metallic, roughness] = self.parameters.contents(material);
        [diffuse, coverage, metallic, roughness, self.normal_maps.contents(material)]
    }

    /// Problems met while deriving the world (a texture that could not be decoded).
    pub fn warnings(&self) -> &[String] {
        &self.warnings
    }

    /// The scattering function at a surface point: its material's kind (with the metallic weight
    /// and roughness its textures paint there, if they do) with the colour of its texture there,
    /// or its `Kd`.
    #[inline]
    pub fn bsdf(&self, surface: &SurfacePoint) -> MaterialBsdf {
        let id = surface.material as usize;
        let kind = self.parameters.kind_at(id, surface.uv).unwrap_or(self.kinds[id]);
        kind.bsdf(self.base_colour(surface.material, surface.uv))
    }

    /// The reflectance of the [`World::bsdf`] of material `material` at texture coordinates `uv`,
    /// if that BSDF is Lambertian: what lighting many diffuse receivers together needs, without
    /// building (and copying) a whole BSDF for each.
    #[inline]
    pub fn lambert_reflectance(&self, material: u32, uv: Vec2) -> Option<Vec3> {
        matches!(self.kinds[material as usize], MaterialKind::Lambert).then(|| self.base_colour(material, uv))
    }

    /// Material `material`'s colour at `uv`: its texture's there (placed by its `-s` and `-o`), or its `Kd`.
    #[inline]
    fn base_colour(&self, material: u32, uv: Vec2) -> Vec3 {
        let id = material as usize;
        match self.texture_of_material[id] {
            Some(map) => {
                let colour = self.textures.sample(map.texture, placed_uv(map.placement, uv));
                map.factor.map_or(colour, |factor| colour * factor)
            }
            None => self.scene.materials[id].kd,
        }
    }

    /// The material of triangle `triangle`, as a [`SurfacePoint`] on it holds it.
    #[inline]
    pub fn material_of(&self, triangle: u32) -> u32 {
        self.scene.mesh.material_ids[triangle as usize]
    }

    /// Starts loading the records of `hit`'s triangle that shading reads first (whether it is a
    /// light; for [`World::surface`], its corners' indices and its material), so that other work
    /// can run while they come from memory.
    #[inline]
    pub fn prefetch_hit(&self, hit: &Hit) {
        if !self.prefetches {
            return;
        }
        self.lights.prefetch_light_of(hit.triangle);
        let mesh = &self.scene.mesh;
        let id = hit.triangle as usize;
        prefetch(&mesh.indices[id]);
        prefetch(&mesh.material_ids[id]);
        if let Some(corners) = mesh.normal_indices.get(id) {
            prefetch(corners);
        }
        if let Some(corners) = mesh.texcoord_indices.get(id) {
            prefetch(corners);
        }
    }

    /// Starts loading what [`World::bsdf`] will read at `surface` (its texels), so that other work
    /// can run while they come from memory.
    #[inline]
    pub fn prefetch_bsdf(&self, surface: &SurfacePoint) {
        if !self.prefetches {
            return;
        }
        if let Some(map) = self.texture_of_material[surface.material as usize] {
            self.textures.prefetch(map.texture, placed_uv(map.placement, surface.uv));
        }
    }

    /// The instruction set the BVH was built for.
    pub fn isa(&self) -> Isa {
        self.accel.isa()
    }

    /// Radiance emitted by triangle `id` along `ray` back towards its origin: the emission of a
    /// light seen from the side its winding faces, nothing from behind or from a non-light.
    #[inline]
    pub fn emitted(&self, triangle: u32, ray: &Ray) -> Vec3 {
        self.lights
            .light_of(triangle)
            .map_or(Vec3::ZERO, |index| self.lights.lights()[index as usize].radiance_towards(-ray.dir))
    }

    /// The closest hit along `ray` within `[0, ray.tmax]`.
    #[inline]
    pub fn intersect(&self, ray: &Ray) -> Option<Hit> {
        if self.has_cutouts() {
            return self.accel.intersect_filtered(ray, &|id, u, v| self.opaque_at(id, u, v));
        }
        self.accel.intersect(ray)
    }

    /// [`World::intersect`] for the `live` rays among `N` (bit `i` for ray `i`), traced together
    /// where they are coherent (see [`Accel::intersect_packet`]); the same hits.
    #[inline]
    pub fn intersect_packet<const N: usize>(&self, rays: &[Ray; N], live: u32) -> [Option<Hit>; N] {
        if self.has_cutouts() {
            return std::array::from_fn(
                |lane| if live & (1 << lane) != 0 { self.intersect(&rays[lane]) } else { None },
            );
        }
        self.accel.intersect_packet(rays, live)
    }

    /// [`World::occluded`] for the `live` rays among `N`, traced together where they are coherent;
    /// bit `i` set if ray `i` is blocked.
    #[inline]
    pub fn occluded_packet<const N: usize>(&self, rays: &[Ray; N], live: u32) -> u32 {
        if self.has_cutouts() {
            return self.occluded_one_by_one(live, |lane| rays[lane]);
        }
        self.accel.occluded_packet(rays, live)
    }

    /// Whether anything lies along `ray` within `[0, ray.tmax]`.
    #[inline]
    pub fn occluded(&self, ray: &Ray) -> bool {
        if self.has_cutouts() {
            return self.accel.occluded_filtered(ray, &|id, u, v| self.opaque_at(id, u, v));
        }
        self.accel.occluded(ray)
    }

    /// Whether a material may be cut out (see [`Cutout::may_cut`]): then each ray is traced alone,
    /// and each hit on a cutout material is tested against its coverage.
    #[inline]
    fn has_cutouts(&self) -> bool {
        self.cuts
    }

    /// Bit `lane` set for each `live` lane whose ray `ray(lane)` is blocked, traced one by one.
    fn occluded_one_by_one(&self, live: u32, ray: impl Fn(usize) -> Ray) -> u32 {
        lanes_of(live).fold(0, |blocked, lane| blocked | u32::from(self.occluded(&ray(lane))) << lane)
    }

    /// Whether triangle `id` is there at barycentrics `(u, v)` of its second and third corners:
    /// false where its material's coverage (its `map_d` texture's, or 1) fails the material's test
    /// (below one half, for MTL), the alpha test of cutout leaves and fences; for glTF's `BLEND`,
    /// against a hash of the hit.
    fn opaque_at(&self, id: u32, u: f32, v: f32) -> bool {
        let material = self.scene.mesh.material_ids[id as usize] as usize;
        let Some(Cutout { texture, test }) = self.cutout_of_material[material] else { return true };
        let coverage = texture.map_or(1.0, |(texture, placement)| {
            let uv = placed_uv(placement, self.interpolated_texcoord(id as usize, 1.0 - u - v, u, v));
            let texture = self.cutouts.get(texture);
            if test.alpha_only { texture.sample_alpha(uv) } else { texture.sample_coverage(uv) }
        });
        test.keeps(coverage, || hit_hash(id, u, v))
    }

    /// Readies `batch` for `rays` rays leaving `origin` inside `region`: gathers their candidate
    /// triangles, or notes that they are cheaper traced one by one (see [`OriginBatch`]).
    #[inline]
    pub fn prepare_batch(&self, batch: &mut OriginBatch, origin: Vec3, region: &Region, rays: u32) {
        // A batch's triangles know nothing of cutouts: with them the batch is readied for no rays,
        // so it gathers nothing, and the queries below trace its rays one by one, filtered.
        let rays = if self.has_cutouts() { 0 } else { rays };
        self.accel.prepare_batch(batch, origin, region, rays);
    }

    /// Runs `f` compiled for the ISA of the world's accel (see [`Accel::simd`]).
    #[inline(always)]
    pub fn simd<R>(&self, f: impl FnOnce() -> R) -> R {
        self.accel.simd(f)
    }

    /// Runs `f` compiled for the ISA of the world's accel, at most 256 bits wide (see [`Accel::simd_256`]).
    #[inline(always)]
    pub fn simd_256<R>(&self, f: impl FnOnce() -> R) -> R {
        self.accel.simd_256(f)
    }

    /// Which of the `live` rays among `N` leaving the origin of `batch` with directions `dirs`
    /// (SoA) and one `tmax` are blocked, bit `i` for ray `i` (see [`Accel::occluded_lanes_in_batch`]).
    #[inline(always)]
    pub fn occluded_lanes_in_batch<const N: usize>(
        &self,
        batch: &OriginBatch,
        dirs: &[[f32; N]; 3],
        tmax: f32,
        live: u32,
    ) -> u32 {
        if self.has_cutouts() {
            let origin = batch.origin();
            return self.occluded_one_by_one(live, |lane| Ray { origin, dir: Vec3::from(dirs.map(|d| d[lane])), tmax });
        }
        self.accel.occluded_lanes_in_batch(batch, dirs, tmax, live)
    }

    /// [`World::occluded`] for a ray of a batch prepared with [`World::prepare_batch`].
    #[inline]
    pub fn occluded_in_batch(&self, batch: &OriginBatch, ray: &Ray) -> bool {
        if self.has_cutouts() {
            return self.occluded(ray);
        }
        self.accel.occluded_in_batch(batch, ray)
    }

    /// The surface point of `hit`, found along `ray`.
    pub fn surface(&self, ray: &Ray, hit: &Hit) -> SurfacePoint {
        let mesh = &self.scene.mesh;
        let id = hit.triangle as usize;
        let [p0, p1, p2] = mesh.vertices(id);
        let w = 1.0 - hit.u - hit.v;
        let p = w * p0 + hit.u * p1 + hit.v * p2;
        let geometric = (p1 - p0).cross(p2 - p0).normalize_or_zero();
        let front_face = geometric.dot(ray.dir) <= 0.0;
        let ng = if front_face { geometric } else { -geometric };
        let ns = self.interpolated_normal(id, w, hit.u, hit.v).map_or(ng, |n| if n.dot(ng) < 0.0 { -n } else { n });
        let uv = self.interpolated_texcoord(id, w, hit.u, hit.v);
        let material = mesh.material_ids[id];
        let ns = self.mapped_normal(hit.triangle, material, uv, ns, ng);
        SurfacePoint { p, ng, ns, uv, triangle: hit.triangle, material, front_face }
    }

    /// The shading normal at a hit on triangle `triangle` of material `material` whose
    /// interpolated normal is `ns`: bent by the material's normal map, if it has one
    /// (`world/normals.rs`).
    #[inline]
    fn mapped_normal(&self, triangle: u32, material: u32, uv: Vec2, ns: Vec3, ng: Vec3) -> Vec3 {
        if !self.normal_maps.maps(material) {
            return ns;
        }
        let id = triangle as usize;
        let Some(texcoords) = self.scene.mesh.corner_texcoords(id) else { return ns };
        let corners = Corners { positions: self.scene.mesh.vertices(id), texcoords };
        self.normal_maps.shading_normal(material, &corners, uv, ns, ng)
    }

    /// [`World::surface`] of every lane of `rays` with a hit (default points elsewhere), with its
    /// bits, computed together: the corners gathered lane by lane, the rest in a lane loop in the
    /// ISA's width (`geometry/surface_lanes.rs`).
    #[inline]
    pub fn surfaces<const N: usize>(&self, rays: &[Ray; N], hits: &[Option<Hit>; N]) -> [SurfacePoint; N] {
        let rows = self.surface_rows(rays, hits);
        // A plain loop: through `array::from_fn` the points were a call per lane (materials 6% slower).
        let mut points = [SurfacePoint::default(); N];
        for (lane, hit) in hits.iter().enumerate() {
            if let Some(hit) = hit {
                points[lane] = rows.point(lane, hit.triangle, self.material_of(hit.triangle));
            }
        }
        points
    }

    /// The vectors of [`World::surfaces`], rows by axis (lanes without a hit hold garbage): for
    /// callers that go on working lane by lane in rows, without a point per lane.
    #[inline]
    pub fn surface_rows<const N: usize>(&self, rays: &[Ray; N], hits: &[Option<Hit>; N]) -> SurfaceRows<N> {
        let mesh = &self.scene.mesh;
        let mut corners = HitCorners::<N>::default();
        for (lane, hit) in hits.iter().enumerate() {
            let Some(hit) = hit else { continue };
            let id = hit.triangle as usize;
            // Straight from the index arrays into the rows: through `TriangleMesh::corner_normals`
            // (a copy of the three values first) hard shadows took 2-7% longer.
            let gather = |corners: &mut [Rows<N>; 3], values: &[Vec3], indices: [u32; 3]| {
                for (rows, index) in corners.iter_mut().zip(indices) {
                    set_row(rows, lane, values[index as usize]);
                }
            };
            gather(&mut corners.positions, &mesh.positions, mesh.indices[id]);
            if let Some(&indices) = mesh.normal_indices.get(id)
                && !indices.contains(&NO_INDEX)
            {
                gather(&mut corners.normals, &mesh.normals, indices);
                corners.normals_given[lane] = true;
            }
            if let Some(&indices) = mesh.texcoord_indices.get(id)
                && !indices.contains(&NO_INDEX)
            {
                for (rows, index) in corners.texcoords.iter_mut().zip(indices) {
                    let value = mesh.texcoords[index as usize];
                    (rows[0][lane], rows[1][lane]) = (value.x, value.y);
                }
                corners.texcoords_given[lane] = true;
            }
            (corners.u[lane], corners.v[lane]) = (hit.u, hit.v);
            set_row(&mut corners.dir, lane, rays[lane].dir);
        }
        let mut rows = self.simd_256(
            #[inline(always)]
            || corners.surface_rows(),
        );
        if !self.normal_maps.is_empty() {
            for (lane, hit) in hits.iter().enumerate() {
                let Some(hit) = hit else { continue };
                let (ns, ng) = (row(&rows.ns, lane), row(&rows.ng, lane));
                let uv = Vec2::new(rows.uv[0][lane], rows.uv[1][lane]);
                let ns = self.mapped_normal(hit.triangle, self.material_of(hit.triangle), uv, ns, ng);
                set_row(&mut rows.ns, lane, ns);
            }
        }
        rows
    }

    fn interpolated_normal(&self, id: usize, w: f32, u: f32, v: f32) -> Option<Vec3> {
        let [a, b, c] = self.scene.mesh.corner_normals(id)?;
        (w * a + u * b + v * c).try_normalize()
    }

    fn interpolated_texcoord(&self, id: usize, w: f32, u: f32, v: f32) -> Vec2 {
        self.scene.mesh.corner_texcoords(id).map_or(Vec2::ZERO, |[a, b, c]| w * a + u * b + v * c)
    }
}

/// How a material's surface is cut out: by its coverage texture (with its placement), or without
/// one by its test alone (a glTF material whose factor's alpha covers part of it).
#[derive(Clone, Copy)]
struct Cutout {
    texture: Option<(TextureId, Option<UvTransform>)>,
    test: CoverageTest,
}

impl Cutout {
    /// Whether the cutout may cut its surface: not where only alpha counts, the file has none,
    /// and full coverage passes (a glTF `MASK` material with a JPEG base colour), which would give
    /// up the BVH's fast paths for nothing.
    fn may_cut(&self, textures: &TextureSet) -> bool {
        let opaque_texture = |(id, _): (TextureId, _)| self.test.alpha_only && !textures.get(id).has_alpha();
        !(self.texture.is_none_or(opaque_texture) && self.test.keeps_full_coverage())
    }
}

/// `material`'s cutout, given its coverage texture where one decoded: none for a material that is
/// whole (an emitter always is: see [`Material::cutout_mask`]).
fn cutout(material: &Material, texture: Option<(TextureId, Option<UvTransform>)>) -> Option<Cutout> {
    let test = material.map_d_test;
    let cut_without_texture = !material.is_emissive() && !test.keeps_full_coverage();
    (texture.is_some() || cut_without_texture).then_some(Cutout { texture, test })
}

/// A number in [0, 1) for the hit at barycentrics `(u, v)` of triangle `id`, which a hashed
/// coverage test ([`crate::materials::Cut::Hashed`]) compares with: the same hit always gets the
/// same number, and hits apart get numbers as good as independent.
fn hit_hash(id: u32, u: f32, v: f32) -> f32 {
    let point = mix64(u64::from(u.to_bits()) | u64::from(v.to_bits()) << 32);
    (mix64(point ^ u64::from(id)) >> 40) as f32 * (1.0 / (1u32 << 24) as f32)
}

/// Each material's texture id with that material's placement of it, where it moves the texture.
fn placed(
    ids: Vec<Option<TextureId>>,
    placements: impl Iterator<Item = UvTransform>,
) -> Vec<Option<(TextureId, Option<UvTransform>)>> {
    ids.into_iter()
        .zip(placements.map(UvTransform::moving))
        .map(|(id, placement)| id.map(|id| (id, placement)))
        .collect()
}

/// A material's diffuse texture, with its placement (`-s`, `-o`) and the factor its colour is
/// multiplied by (glTF's `baseColorFactor`), each only where it changes what a lookup gives: most
/// maps have neither, and a lookup then costs what it did without.
#[derive(Clone, Copy)]
struct BaseColourMap {
    texture: TextureId,
    placement: Option<UvTransform>,
    factor: Option<Vec3>,
}

impl BaseColourMap {
    /// The maps of `materials` whose textures decoded (`ids`, one per material).
    fn of_materials(ids: Vec<Option<TextureId>>, materials: &[Material]) -> Vec<Option<BaseColourMap>> {
        let map = |(id, material): (Option<TextureId>, &Material)| {
            Some(BaseColourMap {
                texture: id?,
                placement: material.map_kd_transform.moving(),
                factor: Some(material.map_kd_factor).filter(|&f| f != Vec3::ONE),
            })
        };
        ids.into_iter().zip(materials).map(map).collect()
    }
}

/// Where a texture placed by `placement` is read for the surface's `uv`.
#[inline(always)]
fn placed_uv(placement: Option<UvTransform>, uv: Vec2) -> Vec2 {
    placement.map_or(uv, |p| p.apply(uv))
}
