//! Why an image may come out black, found once for every front end, which says it in its own
//! words (the CLI with its flags, the Python package with its parameters).

use super::RenderOutput;
use crate::integrators::Technique;
use crate::world::World;

/// At most this many material names are given.
const NAMED: usize = 5;

/// What keeps a technique that needs lights in the dark, known before rendering.
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum Unlit {
    /// No material emits: the first materials' names, to make one emit, and how many more there are.
    NoEmitter { materials: Vec<String>, more: usize },
    /// Materials emit, but none of their triangles can become a light (none uses them, or only
    /// triangles of zero area or of an area too large for f32): their names.
    EmittersCannotEmit { materials: Vec<String> },
}

/// Why `technique` will render `world` black for want of lights, or `None` if it has lights or
/// needs none.
pub fn unlit(world: &World, technique: &Technique) -> Option<Unlit> {
    let needs_lights = matches!(technique, Technique::Shadows(_) | Technique::Direct(_) | Technique::Path(_));
    if !needs_lights || !world.lights().is_empty() {
        return None;
    }
    let materials = &world.scene().materials;
    let emitting: Vec<String> =
        materials.iter().filter(|m| m.ke.max_element() > 0.0).take(NAMED).map(|m| format!("{:?}", m.name)).collect();
    if !emitting.is_empty() {
        return Some(Unlit::EmittersCannotEmit { materials: emitting });
    }
    let names: Vec<String> = materials.iter().take(NAMED).map(|m| format!("{:?}", m.name)).collect();
    Some(Unlit::NoEmitter { more: materials.len() - names.len(), materials: names })
}

/// Whether a render that completed passes came out black: no camera ray reached a lit surface.
pub fn is_black(output: &RenderOutput) -> bool {
    output.film.samples > 0 && output.image.pixels.iter().all(|p| p.max_element() <= 0.0)
}

/// What a black image of `technique` says, for the warning: no camera ray hit anything in the hit
/// mask, no camera ray reached a lit surface in the other modes (which the hit mask then checks).
pub fn why_black(technique: &Technique) -> &'static str {
    match technique {
        Technique::Hits(_) => "no camera ray hit the scene; check where the camera looks",
        _ => "no camera ray reached a lit surface; check the camera with the hits mode",
    }
}
