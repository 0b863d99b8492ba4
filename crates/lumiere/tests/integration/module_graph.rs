//! The library's data flows one way (docs/ARCHITECTURE.md): every top-level module may use only the
//! modules listed for it here, which are all below it. A `use crate::…` that adds a back-edge (a
//! loader that reaches into rendering, a BVH that knows materials) fails this test.

use std::collections::{BTreeMap, BTreeSet};
use std::path::Path;

/// Each module and the modules it may use, lowest layer first.
const ALLOWED: &[(&str, &[&str])] = &[
    ("error", &[]),
    ("util", &["error"]),
    ("math", &[]),
    ("sampling", &["math"]),
    ("sampler", &["util"]),
    ("textures", &["error", "math", "util"]),
    ("geometry", &["math"]),
    ("materials", &["error", "math", "sampling", "textures"]),
    ("accel", &["geometry", "math"]),
    ("scene", &["error", "materials", "math", "textures", "util"]),
    ("lights", &["geometry", "math", "sampling", "scene", "util"]),
    ("world", &["accel", "geometry", "lights", "materials", "math", "scene", "textures", "util"]),
    (
        "integrators",
        &["accel", "error", "geometry", "lights", "materials", "math", "sampler", "sampling", "textures", "world"],
    ),
    ("render", &["accel", "error", "integrators", "materials", "math", "sampler", "scene", "util", "world"]),
    ("image_io", &["error", "util"]),
];

/// `crate::<module>` paths used in the code of each top-level module (comments left out: a doc
/// link is not a dependency).
fn used_modules(src: &Path) -> BTreeMap<String, BTreeSet<String>> {
    let mut edges: BTreeMap<String, BTreeSet<String>> = BTreeMap::new();
    let mut stack = vec![src.to_path_buf()];
    while let Some(dir) = stack.pop() {
        for entry in std::fs::read_dir(&dir).unwrap() {
            let path = entry.unwrap().path();
            if path.is_dir() {
                stack.push(path);
                continue;
            }
            let relative = path.strip_prefix(src).unwrap().to_string_lossy().into_owned();
            let top = relative.split('/').next().unwrap().trim_end_matches(".rs").to_string();
            if top == "lib" {
                continue;
            }
            let text = std::fs::read_to_string(&path).unwrap();
            let used = edges.entry(top.clone()).or_default();
            for line in text.lines() {
                let code = line.split("//").next().unwrap();
                for (i, _) in code.match_indices("crate::") {
                    let name: String =
                        code[i + 7..].chars().take_while(|c| c.is_ascii_alphanumeric() || *c == '_').collect();
                    if name != top {
                        used.insert(name);
                    }
                }
            }
        }
    }
    edges
}

#[test]
fn modules_use_only_the_layers_below_them() {
    let src = Path::new(env!("CARGO_MANIFEST_DIR")).join("src");
    let allowed: BTreeMap<&str, &[&str]> = ALLOWED.iter().copied().collect();
    let mut problems = Vec::new();
    for (module, used) in used_modules(&src) {
        let Some(allowed_here) = allowed.get(module.as_str()) else {
            problems.push(format!("module {module} is not in the layer table of this test"));
            continue;
        };
        for target in used.iter().filter(|t| !allowed_here.contains(&t.as_str())) {
            problems.push(format!("{module} uses crate::{target}, which is not below it"));
        }
    }
    assert!(problems.is_empty(), "{}", problems.join("\n"));
}

/// The table itself is a layering: every module's allowed uses come before it in the table, so
/// the graph it permits has no cycle.
#[test]
fn the_layer_table_has_no_cycle() {
    for (i, (module, uses)) in ALLOWED.iter().enumerate() {
        let below: Vec<&str> = ALLOWED[..i].iter().map(|(m, _)| *m).collect();
        for used in *uses {
            assert!(below.contains(used), "{module} may use {used}, which is not listed before it");
        }
    }
}
