//! The camera rig every shape renders its target for, and the target options of a config.

use roar_loss::TargetOptions;
use roar_render::{Camera, star_cameras};

use crate::config::ReconstructConfig;

/// The camera rig of `config` (the star rig, `views_per_axis²` views of
/// `render_resolution²` pixels), for which every shape renders its target.
pub fn rig_cameras(config: &ReconstructConfig) -> Vec<Camera> {
    star_cameras(
        config.target.views_per_axis,
        config.target.views_per_axis,
        config.target.render_resolution,
        config.target.render_resolution,
    )
}

/// The coarse rig of `config`: the rig's views at `render_coarse_resolution²` pixels, for the
/// loop's first `render_coarse_fraction` of iterations (and the polish, see [`coarse_until`]);
/// empty when that fraction rounds to no iteration or the resolution is not below
/// `render_resolution`.
pub fn coarse_rig_cameras(config: &ReconstructConfig) -> Vec<Camera> {
    let resolution = config.loss.render_coarse_resolution;
    if coarse_until(config) == 0 || resolution >= config.target.render_resolution {
        return Vec::new();
    }
    let views = config.target.views_per_axis;
    star_cameras(views, views, resolution, resolution)
}

/// The first iteration rendered with the full rig; the finish's polish counts as iteration
/// `iterations`, so it renders coarse too when the whole loop does and `render_coarse_polish`.
pub(crate) fn coarse_until(config: &ReconstructConfig) -> usize {
    let iterations = config.optimize.iterations;
    let coarse = (config.loss.render_coarse_fraction * iterations as f64).round() as usize;
    if iterations > 0 && coarse >= iterations && config.loss.render_coarse_polish {
        usize::MAX
    } else {
        coarse
    }
}

/// The target renders' options of `config`, as the pipeline uses them.
pub fn target_options(config: &ReconstructConfig) -> TargetOptions {
    TargetOptions {
        views_per_axis: config.target.views_per_axis,
        resolution: config.target.render_resolution,
        twin_ratio: config.target.twin_ratio,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_coarse_rig_is_the_rig_at_the_coarse_resolution_for_the_loop_and_the_polish() {
        let mut config = ReconstructConfig::default();
        let (fine, coarse) = (rig_cameras(&config), coarse_rig_cameras(&config));
        assert_eq!(coarse.len(), fine.len());
        for (c, f) in coarse.iter().zip(&fine) {
            assert_eq!((c.width, c.height), (256, 256));
            assert_eq!((c.view, c.proj), (f.view, f.proj));
        }
        assert_eq!(coarse_until(&config), usize::MAX, "the loop and the polish");
        config.loss.render_coarse_polish = false;
        assert_eq!(coarse_until(&config), 200, "the whole loop only");
        config.loss.render_coarse_polish = true;
        config.loss.render_coarse_fraction = 0.5;
        assert_eq!(coarse_until(&config), 100);
        // None when it would not be coarser, or would render no iteration.
        config.target.render_resolution = 256;
        assert!(coarse_rig_cameras(&config).is_empty());
        config.target.render_resolution = 512;
        config.loss.render_coarse_fraction = 0.0;
        assert!(coarse_rig_cameras(&config).is_empty());
    }
}
