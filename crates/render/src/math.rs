//! Small linear-algebra types: `Vec3` (points, directions and RGB colours), and affine
//! `Transform`s. f32 throughout, as the hot path wants.

use std::ops::{Add, AddAssign, Div, Index, Mul, MulAssign, Neg, Sub, SubAssign};

/// A 3-vector of f32: a point, a direction or a linear RGB colour. Plain data (`Pod`): three
/// floats in order x, y, z, no padding, any bits.
#[derive(Clone, Copy, Debug, Default, PartialEq, bytemuck::Pod, bytemuck::Zeroable)]
#[repr(C)]
pub struct Vec3 {
    pub x: f32,
    pub y: f32,
    pub z: f32,
}

/// Linear RGB. The course calls these colours and light "intensities"; values may exceed 1.
pub type Color = Vec3;

impl Vec3 {
    pub const ZERO: Vec3 = Vec3::new(0.0, 0.0, 0.0);
    pub const ONE: Vec3 = Vec3::new(1.0, 1.0, 1.0);
    pub const X: Vec3 = Vec3::new(1.0, 0.0, 0.0);
    pub const Y: Vec3 = Vec3::new(0.0, 1.0, 0.0);
    pub const Z: Vec3 = Vec3::new(0.0, 0.0, 1.0);

    #[inline]
    pub const fn new(x: f32, y: f32, z: f32) -> Self {
        Vec3 { x, y, z }
    }
    #[inline]
    pub const fn splat(v: f32) -> Self {
        Vec3 { x: v, y: v, z: v }
    }
    #[inline]
    pub fn dot(self, o: Vec3) -> f32 {
        self.x * o.x + self.y * o.y + self.z * o.z
    }
    #[inline]
    pub fn cross(self, o: Vec3) -> Vec3 {
        Vec3::new(
            self.y * o.z - self.z * o.y,
            self.z * o.x - self.x * o.z,
            self.x * o.y - self.y * o.x,
        )
    }
    #[inline]
    pub fn length_squared(self) -> f32 {
        self.dot(self)
    }
    #[inline]
    pub fn length(self) -> f32 {
        self.length_squared().sqrt()
    }
    /// The unit vector along `self`. A zero vector stays zero rather than becoming NaN.
    #[inline]
    pub fn normalized(self) -> Vec3 {
        let len = self.length();
        if len > 0.0 {
            self / len
        } else {
            Vec3::ZERO
        }
    }
    #[inline]
    pub fn min(self, o: Vec3) -> Vec3 {
        Vec3::new(self.x.min(o.x), self.y.min(o.y), self.z.min(o.z))
    }
    #[inline]
    pub fn max(self, o: Vec3) -> Vec3 {
        Vec3::new(self.x.max(o.x), self.y.max(o.y), self.z.max(o.z))
    }
    #[inline]
    pub fn abs(self) -> Vec3 {
        Vec3::new(self.x.abs(), self.y.abs(), self.z.abs())
    }
    #[inline]
    pub fn max_component(self) -> f32 {
        self.x.max(self.y).max(self.z)
    }
    #[inline]
    pub fn min_component(self) -> f32 {
        self.x.min(self.y).min(self.z)
    }
    /// Component-wise product (colour modulation).
    #[inline]
    pub fn mul_elem(self, o: Vec3) -> Vec3 {
        Vec3::new(self.x * o.x, self.y * o.y, self.z * o.z)
    }
    #[inline]
    pub fn map(self, f: impl Fn(f32) -> f32) -> Vec3 {
        Vec3::new(f(self.x), f(self.y), f(self.z))
    }
    #[inline]
    pub fn clamp01(self) -> Vec3 {
        self.map(|c| c.clamp(0.0, 1.0))
    }
    #[inline]
    pub fn is_finite(self) -> bool {
        self.x.is_finite() && self.y.is_finite() && self.z.is_finite()
    }
    #[inline]
    pub fn has_nan(self) -> bool {
        self.x.is_nan() || self.y.is_nan() || self.z.is_nan()
    }
    /// Index of the largest component (0, 1 or 2).
    #[inline]
    pub fn max_axis(self) -> usize {
        if self.x >= self.y && self.x >= self.z {
            0
        } else if self.y >= self.z {
            1
        } else {
            2
        }
    }
    #[inline]
    pub fn to_array(self) -> [f32; 3] {
        [self.x, self.y, self.z]
    }
    #[inline]
    pub fn from_array(a: [f32; 3]) -> Vec3 {
        Vec3::new(a[0], a[1], a[2])
    }
    #[inline]
    pub fn luminance(self) -> f32 {
        0.2126 * self.x + 0.7152 * self.y + 0.0722 * self.z
    }
}

impl Index<usize> for Vec3 {
    type Output = f32;
    #[inline]
    fn index(&self, i: usize) -> &f32 {
        match i {
            0 => &self.x,
            1 => &self.y,
            _ => &self.z,
        }
    }
}

macro_rules! vec_binop {
    ($trait:ident, $fn:ident, $atrait:ident, $afn:ident, $op:tt) => {
        impl $trait for Vec3 {
            type Output = Vec3;
            #[inline]
            fn $fn(self, o: Vec3) -> Vec3 {
                Vec3::new(self.x $op o.x, self.y $op o.y, self.z $op o.z)
            }
        }
        impl $atrait for Vec3 {
            #[inline]
            fn $afn(&mut self, o: Vec3) {
                *self = *self $op o;
            }
        }
    };
}
vec_binop!(Add, add, AddAssign, add_assign, +);
vec_binop!(Sub, sub, SubAssign, sub_assign, -);

impl Mul<f32> for Vec3 {
    type Output = Vec3;
    #[inline]
    fn mul(self, s: f32) -> Vec3 {
        Vec3::new(self.x * s, self.y * s, self.z * s)
    }
}
impl Mul<Vec3> for f32 {
    type Output = Vec3;
    #[inline]
    fn mul(self, v: Vec3) -> Vec3 {
        v * self
    }
}
impl MulAssign<f32> for Vec3 {
    #[inline]
    fn mul_assign(&mut self, s: f32) {
        *self = *self * s;
    }
}
impl Div<f32> for Vec3 {
    type Output = Vec3;
    #[inline]
    fn div(self, s: f32) -> Vec3 {
        let inv = 1.0 / s;
        self * inv
    }
}
impl Neg for Vec3 {
    type Output = Vec3;
    #[inline]
    fn neg(self) -> Vec3 {
        Vec3::new(-self.x, -self.y, -self.z)
    }
}

/// A 4x4 matrix of f64, row-major, used only while building scenes (composition and inversion
/// need the extra precision far more than speed). The last row of an affine matrix is (0,0,0,1).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Matrix4 {
    pub m: [[f64; 4]; 4],
}

impl Matrix4 {
    pub const IDENTITY: Matrix4 = Matrix4 {
        m: [
            [1.0, 0.0, 0.0, 0.0],
            [0.0, 1.0, 0.0, 0.0],
            [0.0, 0.0, 1.0, 0.0],
            [0.0, 0.0, 0.0, 1.0],
        ],
    };

    pub fn translate(t: Vec3) -> Matrix4 {
        let mut r = Matrix4::IDENTITY;
        r.m[0][3] = t.x as f64;
        r.m[1][3] = t.y as f64;
        r.m[2][3] = t.z as f64;
        r
    }

    pub fn scale(s: Vec3) -> Matrix4 {
        let mut r = Matrix4::IDENTITY;
        r.m[0][0] = s.x as f64;
        r.m[1][1] = s.y as f64;
        r.m[2][2] = s.z as f64;
        r
    }

    /// The standard right-handed rotation about a coordinate axis (0 = X, 1 = Y, 2 = Z) by
    /// `degrees` (lecture slide002 p.21).
    pub fn rotate(axis: usize, degrees: f64) -> Matrix4 {
        let (s, c) = degrees.to_radians().sin_cos();
        let mut r = Matrix4::IDENTITY;
        let (a, b) = match axis {
            0 => (1, 2),
            1 => (2, 0),
            _ => (0, 1),
        };
        r.m[a][a] = c;
        r.m[a][b] = -s;
        r.m[b][a] = s;
        r.m[b][b] = c;
        r
    }

    pub fn mul(&self, o: &Matrix4) -> Matrix4 {
        let mut r = [[0.0; 4]; 4];
        for (i, row) in r.iter_mut().enumerate() {
            for (j, cell) in row.iter_mut().enumerate() {
                *cell = (0..4).map(|k| self.m[i][k] * o.m[k][j]).sum();
            }
        }
        Matrix4 { m: r }
    }

    /// The inverse by Gauss-Jordan elimination with partial pivoting; `None` when singular.
    pub fn inverse(&self) -> Option<Matrix4> {
        let mut a = self.m;
        let mut inv = Matrix4::IDENTITY.m;
        for col in 0..4 {
            let pivot = (col..4).max_by(|&i, &j| a[i][col].abs().total_cmp(&a[j][col].abs()))?;
            if a[pivot][col].abs() < 1e-12 {
                return None;
            }
            a.swap(col, pivot);
            inv.swap(col, pivot);
            let p = a[col][col];
            for j in 0..4 {
                a[col][j] /= p;
                inv[col][j] /= p;
            }
            for i in 0..4 {
                if i != col {
                    let f = a[i][col];
                    if f != 0.0 {
                        for j in 0..4 {
                            a[i][j] -= f * a[col][j];
                            inv[i][j] -= f * inv[col][j];
                        }
                    }
                }
            }
        }
        Some(Matrix4 { m: inv })
    }

    pub fn transpose(&self) -> Matrix4 {
        let mut r = [[0.0; 4]; 4];
        for (i, row) in r.iter_mut().enumerate() {
            for (j, cell) in row.iter_mut().enumerate() {
                *cell = self.m[j][i];
            }
        }
        Matrix4 { m: r }
    }

    pub fn transform_point(&self, p: Vec3) -> Vec3 {
        let v = [p.x as f64, p.y as f64, p.z as f64, 1.0];
        let r = |i: usize| (0..4).map(|k| self.m[i][k] * v[k]).sum::<f64>() as f32;
        Vec3::new(r(0), r(1), r(2))
    }

    pub fn transform_vector(&self, d: Vec3) -> Vec3 {
        let v = [d.x as f64, d.y as f64, d.z as f64];
        let r = |i: usize| (0..3).map(|k| self.m[i][k] * v[k]).sum::<f64>() as f32;
        Vec3::new(r(0), r(1), r(2))
    }
}

/// An affine transform kept together with its inverse, in f32 rows of 3x4 for the hot path.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Transform {
    /// Rows of the 3x4 matrix taking object space to world space.
    pub world_from_object: [[f32; 4]; 3],
    /// Rows of the 3x4 matrix taking world space to object space.
    pub object_from_world: [[f32; 4]; 3],
}

impl Transform {
    /// `None` when the matrix cannot be inverted (a zero scale, say): the loader reports that.
    pub fn from_matrix(m: &Matrix4) -> Option<Transform> {
        let inv = m.inverse()?;
        let rows = |m: &Matrix4| {
            let mut r = [[0.0f32; 4]; 3];
            for (i, row) in r.iter_mut().enumerate() {
                for (j, cell) in row.iter_mut().enumerate() {
                    *cell = m.m[i][j] as f32;
                }
            }
            r
        };
        Some(Transform {
            world_from_object: rows(m),
            object_from_world: rows(&inv),
        })
    }

    #[inline]
    fn apply_point(m: &[[f32; 4]; 3], p: Vec3) -> Vec3 {
        Vec3::new(
            m[0][0] * p.x + m[0][1] * p.y + m[0][2] * p.z + m[0][3],
            m[1][0] * p.x + m[1][1] * p.y + m[1][2] * p.z + m[1][3],
            m[2][0] * p.x + m[2][1] * p.y + m[2][2] * p.z + m[2][3],
        )
    }
    #[inline]
    fn apply_vector(m: &[[f32; 4]; 3], v: Vec3) -> Vec3 {
        Vec3::new(
            m[0][0] * v.x + m[0][1] * v.y + m[0][2] * v.z,
            m[1][0] * v.x + m[1][1] * v.y + m[1][2] * v.z,
            m[2][0] * v.x + m[2][1] * v.y + m[2][2] * v.z,
        )
    }
    #[inline]
    pub fn point_to_world(&self, p: Vec3) -> Vec3 {
        Self::apply_point(&self.world_from_object, p)
    }
    #[inline]
    pub fn vector_to_world(&self, v: Vec3) -> Vec3 {
        Self::apply_vector(&self.world_from_object, v)
    }
    #[inline]
    pub fn point_to_object(&self, p: Vec3) -> Vec3 {
        Self::apply_point(&self.object_from_world, p)
    }
    #[inline]
    pub fn vector_to_object(&self, v: Vec3) -> Vec3 {
        Self::apply_vector(&self.object_from_world, v)
    }
    /// Normals go to world space by the transpose of the inverse (slide_Instancing p.51); the
    /// result is not normalised.
    #[inline]
    pub fn normal_to_world(&self, n: Vec3) -> Vec3 {
        let m = &self.object_from_world;
        Vec3::new(
            m[0][0] * n.x + m[1][0] * n.y + m[2][0] * n.z,
            m[0][1] * n.x + m[1][1] * n.y + m[2][1] * n.z,
            m[0][2] * n.x + m[1][2] * n.y + m[2][2] * n.z,
        )
    }
}

/// An orthonormal frame (U, V, W): the local x, y and z axes in world space. The one frame of
/// the renderer: the lecture's camera and sampling bases (`from_two`, `from_one`, where W
/// points against the given vector) and the shading frame around a normal (`from_normal`,
/// W = the normal), with `to_local`/`to_world` between the spaces.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Frame {
    pub u: Vec3,
    pub v: Vec3,
    pub w: Vec3,
}

impl Frame {
    /// A frame whose W is the unit `normal`, continuous everywhere except across n.z = 0 (Duff
    /// et al., "Building an Orthonormal Frame, Revisited", 2017): branch-free and exact, unlike
    /// the cross product with a fixed helper axis.
    #[inline]
    pub fn from_normal(normal: Vec3) -> Frame {
        let sign = 1.0f32.copysign(normal.z);
        let a = -1.0 / (sign + normal.z);
        let b = normal.x * normal.y * a;
        Frame {
            u: Vec3::new(
                1.0 + sign * normal.x * normal.x * a,
                sign * b,
                -sign * normal.x,
            ),
            v: Vec3::new(b, sign + normal.y * normal.y * a, -normal.y),
            w: normal,
        }
    }

    /// World-space `v` in this frame's coordinates.
    #[inline]
    pub fn to_local(self, v: Vec3) -> Vec3 {
        Vec3::new(v.dot(self.u), v.dot(self.v), v.dot(self.w))
    }

    /// Frame coordinates `v` in world space.
    #[inline]
    pub fn to_world(self, v: Vec3) -> Vec3 {
        self.u * v.x + self.v * v.y + self.w * v.z
    }

    /// The lecture's basis from two vectors (slide001 p.20): W = -a/|a|, U = b x W / |b x W|,
    /// V = W x U, with `a` the gaze and `b` the up vector.
    ///
    /// Degenerate case (FORMAT.md A1): when the gaze is (nearly) parallel to up the cross product
    /// vanishes. We then follow the instructor-era student code (KV `CoordSys.cpp`) and use
    /// b = (1,0,0) instead, except that we take whichever coordinate axis is least parallel to the
    /// gaze, so the frame is well defined for any gaze. For the course's straight-down camera
    /// (`StanfordBunny.json`, gaze (0,-1,0)) that is X, exactly KV's choice.
    pub fn from_two(a: Vec3, b: Vec3) -> Frame {
        let w = -a.normalized();
        let mut u = b.cross(w);
        if u.length_squared() < 1e-12 * b.length_squared().max(1e-30) || !u.is_finite() {
            let alt = least_parallel_axis(w);
            u = alt.cross(w);
        }
        let u = u.normalized();
        let v = w.cross(u);
        Frame { u, v, w }
    }

    /// The lecture's basis from one vector (slide001 p.18): W = -a/|a|, t = W with its
    /// smallest-magnitude component replaced by 1, U = t x W / |t x W|, V = W x U.
    pub fn from_one(a: Vec3) -> Frame {
        let w = -a.normalized();
        let abs = w.abs();
        let mut t = w;
        if abs.x <= abs.y && abs.x <= abs.z {
            t.x = 1.0;
        } else if abs.y <= abs.z {
            t.y = 1.0;
        } else {
            t.z = 1.0;
        }
        let u = t.cross(w).normalized();
        let v = w.cross(u);
        Frame { u, v, w }
    }
}

fn least_parallel_axis(w: Vec3) -> Vec3 {
    let a = w.abs();
    if a.x <= a.y && a.x <= a.z {
        Vec3::X
    } else if a.y <= a.z {
        Vec3::Y
    } else {
        Vec3::Z
    }
}
