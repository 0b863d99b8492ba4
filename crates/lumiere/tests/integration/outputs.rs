//! Outputs never overwrite an input or each other (`util::overwrite`), and writes through a
//! symbolic link replace the file it points to, never the link (`util::write`).

use std::fs;
use std::path::Path;

use crate::common::TempDir;
use lumiere::Error;
use lumiere::util::overwrite::{Named, check_outputs, check_scene_files};
use lumiere::util::write::{check_writable, write_atomically};

fn named<'a>(name: &'a str, path: &'a Path) -> Named<'a> {
    Named { name, path }
}

fn invalid(result: lumiere::Result<()>) -> String {
    match result {
        Err(Error::Invalid(message)) => message,
        other => panic!("expected Error::Invalid, got {other:?}"),
    }
}

/// Distinct files pass, existing or not, and whatever their names; one file reached two ways (a hard
/// link, a folder named twice, a bare name and its absolute path) clashes, as outputs and as an
/// output over an input.
#[test]
fn outputs_clash_exactly_when_they_are_one_file() {
    let dir = TempDir::new("clash");
    let (a, b) = (dir.write("a.exr", "a"), dir.write("b.exr", "b"));
    fs::create_dir(dir.path("x")).unwrap();
    fs::create_dir(dir.path("y")).unwrap();
    // Distinct existing files, distinct new files, and new files of one name in two folders.
    let (new_x, new_y) = (dir.path("x/out.png"), dir.path("y/out.png"));
    let distinct = [named("-o", &a), named("--checkpoint", &b), named("--stats", &new_x), named("--aov", &new_y)];
    check_outputs(&distinct, &[], None).expect("four distinct outputs");
    check_outputs(&distinct[..1], &[named("the scene", &b), named("the orbiter", &new_x)], None)
        .expect("an output beside its inputs");
    check_scene_files([a.as_path(), new_x.as_path()], [b.as_path(), new_y.as_path()]).expect("distinct files");

    // One existing file under two names (a hard link): the same device and inode.
    let link = dir.path("link.exr");
    fs::hard_link(&a, &link).unwrap();
    let message = invalid(check_outputs(&[named("-o", &a), named("--aov", &link)], &[], None));
    assert!(message.ends_with("are the same file: both outputs"), "{message}");
    let message = invalid(check_outputs(&[named("-o", &link)], &[named("the scene", &a)], None));
    assert!(message.ends_with("an output would overwrite an input"), "{message}");
    let message = invalid(check_scene_files([link.as_path()], [b.as_path(), a.as_path()]));
    assert!(message.ends_with("which the scene reads"), "{message}");

    // A new file named through its folder twice.
    let again = dir.path("y/../x/out.png");
    let message = invalid(check_outputs(&[named("-o", &new_x), named("--stats", &again)], &[], None));
    assert!(message.ends_with("both outputs"), "{message}");

    // A bare name (no folder: the current one) and its absolute path; nothing is created.
    let bare = Path::new("lumiere-test-never-written.exr");
    let absolute = std::env::current_dir().unwrap().join(bare);
    assert!(!absolute.exists());
    let message = invalid(check_outputs(&[named("-o", bare), named("--aov", &absolute)], &[], None));
    assert!(message.ends_with("both outputs"), "{message}");
    assert_eq!(dir.entries(), ["a.exr", "b.exr", "link.exr", "x", "y"]);
}

/// Only the pair named as in place (a checkpoint continued where it is) may be one file: the same
/// output over another input, or another output over that input, is refused.
#[test]
fn only_the_in_place_pair_may_be_one_file() {
    let dir = TempDir::new("in-place");
    let checkpoint = dir.write("run.ckpt", "checkpoint");
    let outputs = [named("--checkpoint", &checkpoint)];
    let inputs = [named("--resume", &checkpoint)];
    check_outputs(&outputs, &inputs, Some(("--checkpoint", "--resume"))).expect("continued in place");
    for in_place in [None, Some(("--checkpoint", "--orbiter")), Some(("-o", "--resume"))] {
        let message = invalid(check_outputs(&outputs, &inputs, in_place));
        assert!(message.contains("(--checkpoint) and ") && message.contains("(--resume)"), "{message}");
    }
}

/// A write through a symbolic link replaces the file the link points to, and the link stays; a
/// link to nothing is refused before anything is written.
#[cfg(unix)]
#[test]
fn writes_through_a_link_replace_its_target() {
    let dir = TempDir::new("through-link");
    let target = dir.write("target.json", "old");
    let link = dir.path("link.json");
    std::os::unix::fs::symlink(&target, &link).unwrap();
    check_writable(&link).expect("a link to a file");
    write_atomically(&link, b"new").expect("write through the link");
    assert!(fs::symlink_metadata(&link).unwrap().file_type().is_symlink(), "the link itself was replaced");
    assert_eq!(fs::read(&target).unwrap(), b"new");
    assert_eq!(dir.entries(), ["link.json", "target.json"]);

    let dangling = dir.path("dangling.json");
    std::os::unix::fs::symlink(dir.path("nowhere.json"), &dangling).unwrap();
    assert!(invalid(write_atomically(&dangling, b"x")).contains("is a link to nothing"));
    assert!(invalid(check_writable(&dangling)).contains("is a link to nothing"));
    assert_eq!(dir.entries(), ["dangling.json", "link.json", "target.json"]);
}
