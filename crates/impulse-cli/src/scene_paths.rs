//! Mesh files of a scene written somewhere else: `impulse export SCENE --out FILE` keeps each
//! relative `file` of a triangle mesh pointing at the same file from FILE's directory.

use std::path::{Path, PathBuf};

use impulse::scene::{Scene, ShapeDesc};

/// Rewrites every relative mesh `file` of `scene` (relative to `from`, the directory of the
/// scene file it was read from) so that it names the same file relative to the directory of
/// `out`, the file the scene is written to: as a relative path when one leads there
/// (`pathdiff`), else as an absolute one. Absolute paths and a scene written to its own
/// directory are left as they are, so exporting into `scenes/` keeps `"mug.obj"`; so is a
/// scene whose directories cannot be read (the write then fails on its own).
pub(crate) fn rebase_mesh_files(scene: &mut Scene, from: &Path, out: &Path) {
    let to = out.parent().unwrap_or(Path::new(""));
    let (Ok(from), Ok(to)) = (canonical(from), canonical(to)) else {
        return;
    };
    if from == to {
        return;
    }
    for body in &mut scene.bodies {
        rebase_shape(&mut body.shape, &from, &to);
    }
}

/// The canonical form of directory `path` (`""` is the current directory): absolute, with no
/// `..` for `pathdiff` to trip on.
fn canonical(path: &Path) -> std::io::Result<PathBuf> {
    let path = if path.as_os_str().is_empty() {
        Path::new(".")
    } else {
        path
    };
    std::fs::canonicalize(path)
}

fn rebase_shape(shape: &mut ShapeDesc, from: &Path, to: &Path) {
    match shape {
        ShapeDesc::Trimesh {
            file: Some(file), ..
        } if Path::new(file.as_str()).is_relative() => {
            let target = from.join(file.as_str());
            let rebased = pathdiff::diff_paths(&target, to).unwrap_or(target);
            *file = rebased.to_string_lossy().into_owned();
        }
        ShapeDesc::Round { shape, .. } | ShapeDesc::Thickened { shape, .. } => {
            rebase_shape(shape, from, to)
        }
        _ => {}
    }
}
