//! Cost and checksum of one evaluation of the default objective (render + planar)
//! on the real working mesh of a run, for profiling the loop's loss.
//!
//! Two steps, so the slow preparation (target, init, point cloud) runs once:
//!
//! - `loss_profile dump MESH STATE [FACES] [AT]` runs the pipeline on `MESH` (default 5000 faces)
//!   until the loss is evaluated for the `AT`-th time (default 0: the first loop iteration) and
//!   writes the point cloud and that working mesh to the file `STATE`.
//! - `loss_profile eval MESH STATE [EVALS] [TERM]` rebuilds the target of `MESH` (its renders),
//!   reads `STATE` and evaluates the loss `EVALS` times (default 3); `TERM` = `all` (default),
//!   `render` or `planar`. Prints the wall time of each evaluation and a checksum of the bits of
//!   every value and gradient, which changes if any output bit changes.
//!
//! With env `SINGLE=1` everything runs in a one-thread rayon pool on the main thread, so that
//! `SINGLE=1 valgrind --tool=callgrind --collect-atstart=no --toggle-collect=PATTERN` counts the
//! instructions of the evaluations only. `PATTERN` must match the outermost loss only:
//! `--toggle-collect` flips collection on entry and exit of every matching function, so a
//! pattern like `*value_and_grad*` that also matches the nested terms switches collection off
//! again inside them and counts almost nothing. Use `'*WeightedSum*value_and_grad*'` for
//! `all`, `'*RenderLoss*value_and_grad*'` for `render` and `'*PlanarLoss*value_and_grad*'`
//! for `planar`.

use std::io::{Read, Write};
use std::path::Path;
use std::time::Instant;

use glam::DVec3;
use roar::{
    OptimizeConfig, PipelineError, Prepared, ReconstructConfig, Reconstruction, default_loss,
    planar_options, target_options,
};
use roar_loss::{Loss, LossError, PlanarLoss, PointCloud, RenderLoss, build_target};

/// Any error, as one line for the terminal.
type Result<T, E = Box<dyn std::error::Error>> = std::result::Result<T, E>;

fn main() -> Result<()> {
    let args: Vec<String> = std::env::args().collect();
    if std::env::var_os("SINGLE").is_some() {
        rayon::ThreadPoolBuilder::new()
            .num_threads(1)
            .use_current_thread()
            .build_global()?;
    }
    let usage = "usage: loss_profile dump MESH STATE [FACES] [AT] | eval MESH STATE [EVALS] [TERM]";
    let (Some(mode), Some(mesh), Some(state)) = (args.get(1), args.get(2), args.get(3)) else {
        return Err(usage.into());
    };
    match mode.as_str() {
        "dump" => {
            let faces = args.get(4).map_or(Ok(5000), |a| a.parse())?;
            let at = args.get(5).map_or(Ok(0), |a| a.parse())?;
            dump(Path::new(mesh), Path::new(state), faces, at)
        }
        "eval" => {
            let evals = args.get(4).map_or(Ok(3), |a| a.parse())?;
            let term = args.get(5).map_or("all", |a| a.as_str());
            eval(Path::new(mesh), Path::new(state), evals, term)
        }
        _ => Err(usage.into()),
    }
}

/// The default loss; on its `at`-th evaluation writes the cloud and the mesh to `path` and
/// fails, which ends the run.
struct Dumper {
    inner: Box<dyn Loss>,
    cloud: PointCloud,
    path: std::path::PathBuf,
    calls: usize,
    at: usize,
}

impl Loss for Dumper {
    fn name(&self) -> &'static str {
        "dumper"
    }

    fn value_and_grad(
        &mut self,
        positions: &[DVec3],
        triangles: &[[u32; 3]],
    ) -> Result<(f64, Vec<DVec3>), LossError> {
        if self.calls == self.at {
            write_state(&self.path, &self.cloud, positions, triangles)
                .map_err(|e| LossError::InvalidMesh(format!("dump failed: {e}")))?;
            return Err(LossError::InvalidMesh("dumped, stopping".into()));
        }
        self.calls += 1;
        self.inner.value_and_grad(positions, triangles)
    }
}

fn dump(mesh: &Path, state: &Path, faces: usize, at: usize) -> Result<()> {
    let soup = roar_io::read_mesh(mesh)?;
    let config = ReconstructConfig {
        faces,
        optimize: OptimizeConfig {
            iterations: at + 1,
            ..Default::default()
        },
        ..ReconstructConfig::default()
    };
    let mut run = Reconstruction::new(config);
    let path = state.to_path_buf();
    run.loss_factory = Box::new(
        move |prepared: &Prepared| -> Result<Box<dyn Loss>, PipelineError> {
            Ok(Box::new(Dumper {
                inner: default_loss(prepared)?,
                cloud: prepared.cloud.clone(),
                path: path.clone(),
                calls: 0,
                at,
            }))
        },
    );
    let result = run.run_soup(&soup.positions, &soup.triangles, &mut |_| {});
    match result {
        Err(e) if e.to_string().contains("dumped, stopping") => {
            println!("wrote {}", state.display());
            Ok(())
        }
        Err(e) => Err(e.into()),
        Ok(_) => Err(format!("the run ended before evaluation {at}").into()),
    }
}

fn write_state(
    path: &Path,
    cloud: &PointCloud,
    positions: &[DVec3],
    triangles: &[[u32; 3]],
) -> std::io::Result<()> {
    let mut bytes = Vec::new();
    let put_f64 = |bytes: &mut Vec<u8>, v: f64| bytes.extend_from_slice(&v.to_le_bytes());
    bytes.extend_from_slice(&(cloud.points.len() as u64).to_le_bytes());
    for (p, n) in cloud.points.iter().zip(&cloud.normals) {
        for v in p.to_array().into_iter().chain(n.to_array()) {
            put_f64(&mut bytes, v);
        }
    }
    bytes.extend_from_slice(&(positions.len() as u64).to_le_bytes());
    for p in positions {
        for v in p.to_array() {
            put_f64(&mut bytes, v);
        }
    }
    bytes.extend_from_slice(&(triangles.len() as u64).to_le_bytes());
    for t in triangles {
        for v in t {
            bytes.extend_from_slice(&v.to_le_bytes());
        }
    }
    std::fs::File::create(path)?.write_all(&bytes)
}

/// The cloud's points and normals, the mesh's positions and triangles.
type State = (Vec<DVec3>, Vec<DVec3>, Vec<DVec3>, Vec<[u32; 3]>);

/// Reads little-endian numbers from the front of a byte slice.
struct Cursor<'a> {
    bytes: &'a [u8],
}

impl Cursor<'_> {
    fn take<const N: usize>(&mut self) -> Result<[u8; N]> {
        let Some((head, rest)) = self.bytes.split_first_chunk::<N>() else {
            return Err("truncated state file".into());
        };
        self.bytes = rest;
        Ok(*head)
    }

    fn len(&mut self) -> Result<usize> {
        Ok(u64::from_le_bytes(self.take()?) as usize)
    }

    fn vec3(&mut self) -> Result<DVec3> {
        let mut v = [0.0; 3];
        for x in &mut v {
            *x = f64::from_le_bytes(self.take()?);
        }
        Ok(DVec3::from_array(v))
    }
}

fn read_state(path: &Path) -> Result<State> {
    let mut bytes = Vec::new();
    std::fs::File::open(path)?.read_to_end(&mut bytes)?;
    let mut cursor = Cursor { bytes: &bytes };
    let n_cloud = cursor.len()?;
    let (mut points, mut normals) = (Vec::new(), Vec::new());
    for _ in 0..n_cloud {
        points.push(cursor.vec3()?);
        normals.push(cursor.vec3()?);
    }
    let nv = cursor.len()?;
    let positions = (0..nv).map(|_| cursor.vec3()).collect::<Result<Vec<_>>>()?;
    let nt = cursor.len()?;
    let mut triangles = Vec::with_capacity(nt);
    for _ in 0..nt {
        let mut t = [0u32; 3];
        for v in &mut t {
            *v = u32::from_le_bytes(cursor.take()?);
        }
        triangles.push(t);
    }
    Ok((points, normals, positions, triangles))
}

/// FNV-1a over the bits of a value and a gradient, chained through `hash`.
fn fold_bits(hash: u64, value: f64, grad: &[DVec3]) -> u64 {
    let mut h = hash;
    let bits = std::iter::once(value).chain(grad.iter().flat_map(|g| g.to_array()));
    for x in bits {
        for byte in x.to_bits().to_le_bytes() {
            h ^= byte as u64;
            h = h.wrapping_mul(0x100_0000_01b3);
        }
    }
    h
}

fn eval(mesh: &Path, state: &Path, evals: usize, term: &str) -> Result<()> {
    let config = ReconstructConfig::default();
    let soup = roar_io::read_mesh(mesh)?;
    let (points, normals, positions, triangles) = read_state(state)?;
    let cloud = PointCloud { points, normals };
    println!(
        "cloud {} points, working mesh {} vertices {} faces",
        cloud.points.len(),
        positions.len(),
        triangles.len()
    );
    let planar = || -> Result<Box<dyn Loss>> {
        Ok(Box::new(PlanarLoss::new(
            &cloud.points,
            &cloud.normals,
            &planar_options(&config),
        )?))
    };
    let options = target_options(&config);
    let mut loss: Box<dyn Loss> = match term {
        "planar" => planar()?,
        "render" | "all" => {
            let target = build_target(&soup.positions, &soup.triangles, &options)?;
            if term == "render" {
                Box::new(RenderLoss::new(&target))
            } else {
                default_loss(&Prepared {
                    cameras: &target.cameras,
                    renders: &target.renders,
                    coarse_cameras: &[],
                    coarse_renders: &[],
                    cloud: &cloud,
                    signed_distance: None,
                    config: &config,
                })?
            }
        }
        _ => return Err("TERM is all, render or planar".into()),
    };
    let mut hash = 0xcbf2_9ce4_8422_2325;
    for i in 0..evals {
        let start = Instant::now();
        let (value, grad) = loss.value_and_grad(&positions, &triangles)?;
        let ms = start.elapsed().as_secs_f64() * 1e3;
        hash = fold_bits(hash, value, &grad);
        println!("eval {i}: {ms:.1} ms, loss {value:.12e}");
    }
    println!("checksum {hash:016x}");
    Ok(())
}
