//! Cameras and the star rig of Continuous Remeshing that the authors' code renders with
//! (`docs/method.md#target-clean-up-and-renders`), and the world → pixel projection with its
//! Jacobian.
//!
//! Pixel coordinates: x grows to the right, y grows downwards (row 0 is the top row, because the
//! projection flips y); pixel `(i, j)` covers `[i, i+1) × [j, j+1)` and is sampled at its centre
//! `(i + ½, j + ½)`.

use glam::{DMat3, DMat4, DVec3, DVec4};

/// Distance of the rig's cameras from the origin.
pub const CAMERA_DISTANCE: f64 = 10.0;
/// Near plane distance of the rig's frustum.
pub const NEAR: f64 = 1.0;
/// Far plane distance of the rig's frustum.
pub const FAR: f64 = 50.0;

/// A pinhole camera: OpenGL-style view and projection matrices and an image size.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Camera {
    /// World → camera (view) transform; the camera looks down −z.
    pub view: DMat4,
    /// Camera → clip transform (perspective; `w = −z_view`).
    pub proj: DMat4,
    /// Image width in pixels.
    pub width: u32,
    /// Image height in pixels.
    pub height: u32,
}

impl Camera {
    /// `proj · view`, the world → clip matrix.
    pub fn view_proj(&self) -> DMat4 {
        self.proj * self.view
    }

    /// The view matrix as rows (`m[row][col]`), for writing `cameras.json`.
    pub fn view_matrix_row_major(&self) -> [[f64; 4]; 4] {
        row_major(&self.view)
    }

    /// The projection matrix as rows (`m[row][col]`), for writing `cameras.json`.
    pub fn proj_matrix_row_major(&self) -> [[f64; 4]; 4] {
        row_major(&self.proj)
    }

    /// The camera centre in world coordinates.
    pub fn position(&self) -> DVec3 {
        self.view.inverse().transform_point3(DVec3::ZERO)
    }

    /// Number of pixels of one image.
    pub fn num_pixels(&self) -> usize {
        self.width as usize * self.height as usize
    }

    /// Projects a world point to pixel coordinates `(x, y)`, NDC depth `z/w` and clip `w`.
    /// The caller checks `w` against the near plane.
    pub fn project(&self, p: DVec3) -> ProjectedVertex {
        project_with(&self.view_proj(), self.width, self.height, p)
    }
}

fn row_major(m: &DMat4) -> [[f64; 4]; 4] {
    [0, 1, 2, 3].map(|r| m.row(r).to_array())
}

/// A vertex projected into one view.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ProjectedVertex {
    /// Pixel x (right).
    pub x: f64,
    /// Pixel y (down).
    pub y: f64,
    /// NDC depth `z/w` (smaller is nearer), used only for the z-buffer.
    pub z: f64,
    /// Clip x.
    pub cx: f64,
    /// Clip y.
    pub cy: f64,
    /// Clip w (`= −z_view`, the distance along the viewing axis).
    pub w: f64,
}

/// Projects `p` with the world → clip matrix `m` onto a `width × height` image.
pub fn project_with(m: &DMat4, width: u32, height: u32, p: DVec3) -> ProjectedVertex {
    let c = *m * DVec4::new(p.x, p.y, p.z, 1.0);
    let (hw, hh) = (0.5 * width as f64, 0.5 * height as f64);
    ProjectedVertex {
        x: (c.x / c.w + 1.0) * hw,
        y: (c.y / c.w + 1.0) * hh,
        z: c.z / c.w,
        cx: c.x,
        cy: c.y,
        w: c.w,
    }
}

/// Backward of [`project_with`]: turns a gradient `(gx, gy)` on the pixel coordinates of a
/// projected vertex into a gradient on its world position.
pub fn project_backward(
    m: &DMat4,
    width: u32,
    height: u32,
    v: &ProjectedVertex,
    gx: f64,
    gy: f64,
) -> DVec3 {
    let (hw, hh) = (0.5 * width as f64, 0.5 * height as f64);
    let inv_w = 1.0 / v.w;
    let g_cx = gx * hw * inv_w;
    let g_cy = gy * hh * inv_w;
    let g_cw = -(gx * hw * v.cx + gy * hh * v.cy) * inv_w * inv_w;
    let (r0, r1, r3) = (m.row(0), m.row(1), m.row(3));
    DVec3::new(
        g_cx * r0.x + g_cy * r1.x + g_cw * r3.x,
        g_cx * r0.y + g_cy * r1.y + g_cw * r3.y,
        g_cx * r0.z + g_cy * r1.z + g_cw * r3.z,
    )
}

/// The rig's perspective frustum: near 1, far 50, symmetric half-extent `1/distance` at the
/// near plane (nearly orthographic: a sphere of radius 1 at the origin just fills the frame),
/// y flipped.
pub fn star_projection() -> DMat4 {
    let r = 1.0 / CAMERA_DISTANCE;
    let (n, f) = (NEAR, FAR);
    DMat4::from_cols(
        DVec4::new(n / r, 0.0, 0.0, 0.0),
        DVec4::new(0.0, -n / r, 0.0, 0.0),
        DVec4::new(0.0, 0.0, -(f + n) / (f - n), -1.0),
        DVec4::new(0.0, 0.0, -2.0 * f * n / (f - n), 0.0),
    )
}

/// The star rig: `n_az × n_pol` cameras (the paper's 6 × 6 = 36), index
/// `a · n_pol + p`, with azimuth `φ_a = a·2π/n_az` about world y, polar angle
/// `θ_p = (p+1)·π/(n_pol+1) − π/2` about x, view `T(0,0,−10)·R_x(θ_p)·R_y(φ_a)`, and the
/// frustum of [`star_projection`].
pub fn star_cameras(n_az: usize, n_pol: usize, width: u32, height: u32) -> Vec<Camera> {
    let proj = star_projection();
    let mut cameras = Vec::with_capacity(n_az * n_pol);
    for a in 0..n_az {
        let phi = a as f64 * std::f64::consts::TAU / n_az as f64;
        for p in 0..n_pol {
            let theta = (p + 1) as f64 * std::f64::consts::PI / (n_pol + 1) as f64
                - std::f64::consts::FRAC_PI_2;
            let rot = DMat3::from_rotation_x(theta) * DMat3::from_rotation_y(phi);
            let view = DMat4::from_translation(DVec3::new(0.0, 0.0, -CAMERA_DISTANCE))
                * DMat4::from_mat3(rot);
            cameras.push(Camera {
                view,
                proj,
                width,
                height,
            });
        }
    }
    cameras
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn rig_has_expected_angles_and_positions() {
        let cams = star_cameras(6, 6, 512, 512);
        assert_eq!(cams.len(), 36);
        for c in &cams {
            assert!((c.position().length() - CAMERA_DISTANCE).abs() < 1e-9);
            // The origin projects to the image centre.
            let o = c.project(DVec3::ZERO);
            assert!((o.x - 256.0).abs() < 1e-9 && (o.y - 256.0).abs() < 1e-9);
            assert!((o.w - CAMERA_DISTANCE).abs() < 1e-9);
        }
        // Camera 0: azimuth 0, polar −π/2 + π/7: rotated about x only.
        let theta = std::f64::consts::PI / 7.0 - std::f64::consts::FRAC_PI_2;
        let expected = DMat3::from_rotation_x(theta).transpose() * DVec3::new(0.0, 0.0, 10.0);
        assert!((cams[0].position() - expected).length() < 1e-9);
    }

    #[test]
    fn unit_sphere_just_fills_frame_and_y_is_flipped() {
        let c = star_cameras(1, 1, 100, 100)[0];
        // Camera 0 of a 1×1 rig looks along −z from +z (θ = 0).
        let up = c.project(DVec3::new(0.0, 1.0, 0.0));
        let right = c.project(DVec3::new(1.0, 0.0, 0.0));
        assert!(up.y < 50.0, "world up must be image top, got {}", up.y);
        assert!(right.x > 50.0);
        assert!(
            (right.x - 100.0).abs() < 1e-9,
            "unit radius fills the frame: {}",
            right.x
        );
    }

    fn fd_check(f: impl Fn(DVec3) -> (f64, f64), p: DVec3, analytic: impl Fn(f64, f64) -> DVec3) {
        let h = 1e-6;
        for (gx, gy) in [(1.0, 0.0), (0.0, 1.0), (0.3, -0.7)] {
            let a = analytic(gx, gy);
            for k in 0..3 {
                let mut e = DVec3::ZERO;
                e[k] = h;
                let (xp, yp) = f(p + e);
                let (xm, ym) = f(p - e);
                let fd = (gx * (xp - xm) + gy * (yp - ym)) / (2.0 * h);
                assert!(
                    (fd - a[k]).abs() < 1e-6 * fd.abs().max(1.0),
                    "{fd} vs {}",
                    a[k]
                );
            }
        }
    }

    #[test]
    fn projection_finite_difference() {
        for cam in star_cameras(3, 2, 64, 48) {
            let m = cam.view_proj();
            let p = DVec3::new(0.3, -0.5, 0.4);
            let v = cam.project(p);
            fd_check(
                |q| {
                    let v = cam.project(q);
                    (v.x, v.y)
                },
                p,
                |gx, gy| project_backward(&m, cam.width, cam.height, &v, gx, gy),
            );
        }
    }
}
