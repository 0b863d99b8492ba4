//! The library's integration tests, linked as one binary (one link instead of eight).

mod common;

mod aovs;
mod bsdfs;
mod bvh;
mod camera;
mod checkpoint;
mod cutouts;
mod estimators;
mod film;
mod gltf_cameras;
mod gltf_loading;
mod hard_shadows;
mod hostile_inputs;
mod image_io;
mod module_graph;
mod obj_loading;
mod outputs;
mod packets;
mod path;
mod ply_loading;
mod quad_lights;
mod range;
mod relief_maps;
mod sampling;
mod seams;
mod textures;
mod triangle;
