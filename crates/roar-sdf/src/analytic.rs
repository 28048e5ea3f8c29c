//! Analytic SDFs from a `.sdf.toml` file: sphere, box, torus, cylinder and capsule, combined by
//! union, intersection and difference, each node with an optional rigid transform and uniform
//! scale. Values and gradients are exact (the gradient of the branch that gives the value at a
//! min/max).
//!
//! Grammar (`docs/sdf.md` has an example): the file has one table `[shape]`, a node. A node has
//! `type` and the fields of its type, and optionally `translate = [x, y, z]`,
//! `rotate = [rx, ry, rz]` (degrees about x, then y, then z) and `scale = s` (uniform, > 0),
//! applied to the node as scale, then rotation, then translation.
//!
//! | type | fields |
//! | --- | --- |
//! | `sphere` | `radius` |
//! | `box` | `half_extents = [a, b, c]` |
//! | `torus` | `major`, `minor` (around the z axis) |
//! | `cylinder` | `radius`, `half_height` (along z, capped) |
//! | `capsule` | `radius`, `half_height` (the segment from −z to +z, rounded) |
//! | `union`, `intersection` | `children = [node, …]` (at least one) |
//! | `difference` | `children` (the first minus all the others) |

use std::path::Path;

use glam::{DMat3, DVec2, DVec3};
use rayon::prelude::*;
use roar_mesh::spatial::{Sdf, SdfCounter, SdfEvaluations};
use serde::Deserialize;

use crate::error::SdfError;

/// One node as written in the file (every field optional; [`Node::from_spec`] checks them).
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
struct NodeSpec {
    #[serde(rename = "type")]
    kind: String,
    radius: Option<f64>,
    half_extents: Option<[f64; 3]>,
    half_height: Option<f64>,
    major: Option<f64>,
    minor: Option<f64>,
    children: Option<Vec<NodeSpec>>,
    translate: Option<[f64; 3]>,
    rotate: Option<[f64; 3]>,
    scale: Option<f64>,
}

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
struct FileSpec {
    shape: NodeSpec,
}

#[derive(Clone, Debug)]
enum Primitive {
    Sphere { radius: f64 },
    Box { half: DVec3 },
    Torus { major: f64, minor: f64 },
    Cylinder { radius: f64, half_height: f64 },
    Capsule { radius: f64, half_height: f64 },
}

#[derive(Clone, Copy, Debug)]
enum Combine {
    Union,
    Intersection,
    Difference,
}

#[derive(Clone, Debug)]
enum Shape {
    Primitive(Primitive),
    Combination(Combine, Vec<Node>),
}

/// A node with its transform `p ↦ R·(s·p) + t`.
#[derive(Clone, Debug)]
struct Node {
    shape: Shape,
    rotation: DMat3,
    translation: DVec3,
    scale: f64,
}

impl Node {
    fn from_spec(spec: &NodeSpec, path: &str) -> Result<Self, SdfError> {
        let bad = |m: String| SdfError::Analytic(format!("{path}: {m}"));
        let positive = |name: &str, v: Option<f64>| -> Result<f64, SdfError> {
            match v {
                Some(v) if v.is_finite() && v > 0.0 => Ok(v),
                Some(v) => Err(bad(format!("{name} must be finite and > 0, not {v}"))),
                None => Err(bad(format!("a {} needs `{name}`", spec.kind))),
            }
        };
        let kind = spec.kind.as_str();
        let allowed: &[&str] = match kind {
            "sphere" => &["radius"],
            "box" => &["half_extents"],
            "torus" => &["major", "minor"],
            "cylinder" | "capsule" => &["radius", "half_height"],
            "union" | "intersection" | "difference" => &["children"],
            _ => {
                return Err(bad(format!(
                    "unknown type '{kind}' (sphere, box, torus, cylinder, capsule, union, \
                     intersection, difference)"
                )));
            }
        };
        let given = [
            ("radius", spec.radius.is_some()),
            ("half_extents", spec.half_extents.is_some()),
            ("half_height", spec.half_height.is_some()),
            ("major", spec.major.is_some()),
            ("minor", spec.minor.is_some()),
            ("children", spec.children.is_some()),
        ];
        if let Some((name, _)) = given.iter().find(|(n, g)| *g && !allowed.contains(n)) {
            return Err(bad(format!("a {kind} has no field `{name}`")));
        }
        let shape = match kind {
            "sphere" => Shape::Primitive(Primitive::Sphere {
                radius: positive("radius", spec.radius)?,
            }),
            "box" => {
                let h = spec
                    .half_extents
                    .ok_or_else(|| bad("a box needs `half_extents`".into()))?;
                for v in h {
                    positive("half_extents", Some(v))?;
                }
                Shape::Primitive(Primitive::Box {
                    half: DVec3::from_array(h),
                })
            }
            "torus" => Shape::Primitive(Primitive::Torus {
                major: positive("major", spec.major)?,
                minor: positive("minor", spec.minor)?,
            }),
            "cylinder" => Shape::Primitive(Primitive::Cylinder {
                radius: positive("radius", spec.radius)?,
                half_height: positive("half_height", spec.half_height)?,
            }),
            "capsule" => Shape::Primitive(Primitive::Capsule {
                radius: positive("radius", spec.radius)?,
                half_height: positive("half_height", spec.half_height)?,
            }),
            _ => {
                let combine = match kind {
                    "union" => Combine::Union,
                    "intersection" => Combine::Intersection,
                    _ => Combine::Difference,
                };
                let specs = spec
                    .children
                    .as_deref()
                    .filter(|c| !c.is_empty())
                    .ok_or_else(|| bad(format!("a {kind} needs at least one child")))?;
                let children = specs
                    .iter()
                    .enumerate()
                    .map(|(i, c)| Node::from_spec(c, &format!("{path}.children[{i}]")))
                    .collect::<Result<_, _>>()?;
                Shape::Combination(combine, children)
            }
        };
        let translation = DVec3::from_array(spec.translate.unwrap_or([0.0; 3]));
        let degrees = DVec3::from_array(spec.rotate.unwrap_or([0.0; 3]));
        if !translation.is_finite() || !degrees.is_finite() {
            return Err(bad("translate and rotate must be finite".into()));
        }
        let scale = match spec.scale {
            None => 1.0,
            s => positive("scale", s)?,
        };
        let r = degrees * (std::f64::consts::PI / 180.0);
        let rotation =
            DMat3::from_rotation_z(r.z) * DMat3::from_rotation_y(r.y) * DMat3::from_rotation_x(r.x);
        Ok(Node {
            shape,
            rotation,
            translation,
            scale,
        })
    }

    /// `(f(p), ∇f(p))` in the parent's frame.
    fn eval(&self, p: DVec3) -> (f64, DVec3) {
        let local = self.rotation.transpose() * (p - self.translation) / self.scale;
        let (f, g) = match &self.shape {
            Shape::Primitive(primitive) => primitive.eval(local),
            Shape::Combination(combine, children) => {
                let mut best = children[0].eval(local);
                for child in children.iter().skip(1) {
                    let (f, g) = child.eval(local);
                    best = match combine {
                        Combine::Union if f < best.0 => (f, g),
                        Combine::Intersection if f > best.0 => (f, g),
                        Combine::Difference if -f > best.0 => (-f, -g),
                        _ => best,
                    };
                }
                best
            }
        };
        (self.scale * f, self.rotation * g)
    }
}

/// `t/|t|`, or zero for a zero vector.
fn unit(v: DVec2) -> DVec2 {
    v.normalize_or_zero()
}

impl Primitive {
    fn eval(&self, p: DVec3) -> (f64, DVec3) {
        // Unit radial direction in the xy plane (zero on the axis).
        let radial = DVec3::new(p.x, p.y, 0.0).normalize_or_zero();
        let rho = p.x.hypot(p.y);
        match *self {
            Primitive::Sphere { radius } => (p.length() - radius, p.normalize_or_zero()),
            Primitive::Box { half } => {
                let q = p.abs() - half;
                let sign = DVec3::new(sign(p.x), sign(p.y), sign(p.z));
                let outside = q.max(DVec3::ZERO);
                if outside.length_squared() > 0.0 {
                    (outside.length(), outside.normalize() * sign)
                } else {
                    let axis = if q.x >= q.y && q.x >= q.z {
                        DVec3::X
                    } else if q.y >= q.z {
                        DVec3::Y
                    } else {
                        DVec3::Z
                    };
                    (q.max_element(), axis * sign)
                }
            }
            Primitive::Torus { major, minor } => {
                let q = DVec2::new(rho - major, p.z);
                let u = unit(q);
                (q.length() - minor, u.x * radial + u.y * DVec3::Z)
            }
            Primitive::Cylinder {
                radius,
                half_height,
            } => {
                let d = DVec2::new(rho - radius, p.z.abs() - half_height);
                let axial = DVec3::Z * sign(p.z);
                let outside = d.max(DVec2::ZERO);
                if outside.length_squared() > 0.0 {
                    let u = outside.normalize();
                    (outside.length(), u.x * radial + u.y * axial)
                } else if d.x >= d.y {
                    (d.x, radial)
                } else {
                    (d.y, axial)
                }
            }
            Primitive::Capsule {
                radius,
                half_height,
            } => {
                let c = DVec3::new(0.0, 0.0, p.z.clamp(-half_height, half_height));
                ((p - c).length() - radius, (p - c).normalize_or_zero())
            }
        }
    }
}

fn sign(x: f64) -> f64 {
    if x < 0.0 { -1.0 } else { 1.0 }
}

/// An analytic SDF ([module docs](self): the grammar).
#[derive(Debug)]
pub struct AnalyticSdf {
    root: Node,
    counter: SdfCounter,
}

impl AnalyticSdf {
    /// Parses a `.sdf.toml` document; errors are one line naming the node (`shape.children[1]`).
    pub fn from_toml(text: &str) -> Result<Self, SdfError> {
        let spec: FileSpec =
            toml::from_str(text).map_err(|e| SdfError::Analytic(e.message().replace('\n', " ")))?;
        Ok(Self {
            root: Node::from_spec(&spec.shape, "shape")?,
            counter: SdfCounter::default(),
        })
    }

    /// Reads a `.sdf.toml` file ([`AnalyticSdf::from_toml`]).
    pub fn from_file(path: &Path) -> Result<Self, SdfError> {
        let text = std::fs::read_to_string(path).map_err(|e| SdfError::Io(e.to_string()))?;
        Self::from_toml(&text)
    }
}

impl Sdf for AnalyticSdf {
    fn values(&self, points: &[DVec3], values: &mut [f64]) {
        self.counter.add_values(points.len());
        points
            .par_iter()
            .zip(values)
            .for_each(|(p, v)| *v = self.root.eval(*p).0);
    }

    fn values_and_gradients(&self, points: &[DVec3], values: &mut [f64], gradients: &mut [DVec3]) {
        self.counter.add_gradients(points.len());
        points
            .par_iter()
            .zip(values)
            .zip(gradients)
            .for_each(|((p, v), g)| (*v, *g) = self.root.eval(*p));
    }

    fn evaluations(&self) -> SdfEvaluations {
        self.counter.get()
    }
}
