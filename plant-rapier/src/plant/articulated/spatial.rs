//! Spatial (6-D) motion, force, transform and inertia, as in Featherstone's
//! *Rigid Body Dynamics Algorithms* (2008), §2: motion vectors are
//! [ω; v], force vectors [n; f], both at a frame's origin in its axes.

use nalgebra::{Matrix3, Vector3};

use super::mat3::{mm, mv, outer, tm, tv};

/// A motion vector [ω; v].
#[derive(Debug, Clone, Copy, PartialEq)]
pub(super) struct Motion {
    pub(super) w: Vector3<f64>,
    pub(super) v: Vector3<f64>,
}

/// A force vector [n; f].
#[derive(Debug, Clone, Copy, PartialEq)]
pub(super) struct Force {
    pub(super) n: Vector3<f64>,
    pub(super) f: Vector3<f64>,
}

/// The coordinate transform of motion from frame A to frame B: `e` rotates
/// A's axes into B's, `r` is B's origin in A's coordinates.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(super) struct Xform {
    pub(super) e: Matrix3<f64>,
    pub(super) r: Vector3<f64>,
}

/// A spatial inertia about a frame's origin: mass, first moment m·c and the
/// rotational inertia about the origin (not the centre of mass), which all
/// add linearly when bodies are lumped together.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(super) struct Inertia {
    pub(super) m: f64,
    pub(super) h: Vector3<f64>,
    pub(super) i: Matrix3<f64>,
}

impl Motion {
    pub(super) const ZERO: Self = Self {
        w: Vector3::new(0.0, 0.0, 0.0),
        v: Vector3::new(0.0, 0.0, 0.0),
    };

    pub(super) fn scaled(self, s: f64) -> Self {
        Self {
            w: self.w * s,
            v: self.v * s,
        }
    }

    pub(super) fn add(self, o: Self) -> Self {
        Self {
            w: self.w + o.w,
            v: self.v + o.v,
        }
    }

    /// The motion cross product self ×ₘ m.
    pub(super) fn cross_motion(self, m: Self) -> Self {
        Self {
            w: self.w.cross(&m.w),
            v: self.w.cross(&m.v) + self.v.cross(&m.w),
        }
    }

    /// The force cross product self ×f f.
    pub(super) fn cross_force(self, f: Force) -> Force {
        Force {
            n: self.w.cross(&f.n) + self.v.cross(&f.f),
            f: self.w.cross(&f.f),
        }
    }

    /// The power of force `f` along this motion (a joint's generalised force
    /// when this is its motion subspace).
    pub(super) fn dot(self, f: Force) -> f64 {
        self.w.dot(&f.n) + self.v.dot(&f.f)
    }
}

impl Force {
    pub(super) const ZERO: Self = Self {
        n: Vector3::new(0.0, 0.0, 0.0),
        f: Vector3::new(0.0, 0.0, 0.0),
    };

    pub(super) fn add(self, o: Self) -> Self {
        Self {
            n: self.n + o.n,
            f: self.f + o.f,
        }
    }
}

impl Xform {
    pub(super) const IDENTITY: Self = Self {
        e: Matrix3::new(1.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0),
        r: Vector3::new(0.0, 0.0, 0.0),
    };

    /// A → C from A → B (`self`) then B → C (`then`).
    pub(super) fn then(self, then: Self) -> Self {
        Self {
            e: mm(&then.e, &self.e),
            r: self.r + tv(&self.e, &then.r),
        }
    }

    /// Motion in A's coordinates to B's.
    pub(super) fn motion(&self, m: Motion) -> Motion {
        Motion {
            w: mv(&self.e, &m.w),
            v: mv(&self.e, &(m.v - self.r.cross(&m.w))),
        }
    }

    /// Force in B's coordinates back to A's (the transpose of `motion`).
    pub(super) fn force_back(&self, f: Force) -> Force {
        let ef = tv(&self.e, &f.f);
        Force {
            n: tv(&self.e, &f.n) + self.r.cross(&ef),
            f: ef,
        }
    }

    /// An inertia in B's coordinates back to A's (Xᵀ I X).
    pub(super) fn inertia_back(&self, b: &Inertia) -> Inertia {
        let h = tv(&self.e, &b.h);
        let r = self.r;
        // Σ m (|p'|² 1 − p' p'ᵀ) with p' = Eᵀ p + r, expanded.
        let i = mm(&tm(&self.e, &b.i), &self.e)
            + b.m * (Matrix3::identity() * r.dot(&r) - outer(&r, &r))
            + Matrix3::identity() * (2.0 * r.dot(&h))
            - (outer(&h, &r) + outer(&r, &h));
        Inertia {
            m: b.m,
            h: h + r * b.m,
            i,
        }
    }
}

impl Inertia {
    pub(super) const ZERO: Self = Self {
        m: 0.0,
        h: Vector3::new(0.0, 0.0, 0.0),
        i: Matrix3::new(0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0),
    };

    /// A body of mass `m` with its centre of mass at `c` and inertia
    /// `i_com` about it (both in the frame's axes).
    pub(super) fn from_com(m: f64, c: Vector3<f64>, i_com: Matrix3<f64>) -> Self {
        Self {
            m,
            h: c * m,
            i: i_com + m * (Matrix3::identity() * c.dot(&c) - c * c.transpose()),
        }
    }

    pub(super) fn add(&self, o: &Self) -> Self {
        Self {
            m: self.m + o.m,
            h: self.h + o.h,
            i: self.i + o.i,
        }
    }

    /// The momentum of a body moving with `m`.
    pub(super) fn apply(&self, m: Motion) -> Force {
        Force {
            n: mv(&self.i, &m.w) + self.h.cross(&m.v),
            f: m.v * self.m - self.h.cross(&m.w),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use nalgebra::{Rotation3, Unit};

    fn xf() -> Xform {
        let axis = Unit::new_normalize(Vector3::new(0.3, -0.5, 0.8));
        Xform {
            e: *Rotation3::from_axis_angle(&axis, 0.7).matrix(),
            r: Vector3::new(0.2, -0.1, 0.4),
        }
    }

    fn body() -> Inertia {
        let i = Matrix3::new(0.3, 0.01, -0.02, 0.01, 0.2, 0.03, -0.02, 0.03, 0.1);
        Inertia::from_com(1.7, Vector3::new(0.1, 0.05, -0.2), i)
    }

    /// Power is frame-independent: (X m)·f_B = m·(Xᵀ f_B).
    #[test]
    fn force_back_is_the_transpose_of_motion() {
        let x = xf();
        let m = Motion {
            w: Vector3::new(0.4, -1.0, 2.0),
            v: Vector3::new(-0.3, 0.9, 0.1),
        };
        let f = Force {
            n: Vector3::new(1.5, 0.2, -0.7),
            f: Vector3::new(0.3, -2.0, 0.6),
        };
        assert!((x.motion(m).dot(f) - m.dot(x.force_back(f))).abs() < 1e-12);
    }

    /// Xᵀ I X applied to a motion equals Xᵀ (I (X m)).
    #[test]
    fn inertia_back_matches_the_operator_product() {
        let (x, b) = (xf(), body());
        let m = Motion {
            w: Vector3::new(0.4, -1.0, 2.0),
            v: Vector3::new(-0.3, 0.9, 0.1),
        };
        let direct = x.force_back(b.apply(x.motion(m)));
        let lumped = x.inertia_back(&b).apply(m);
        assert!((direct.n - lumped.n).norm() < 1e-12 && (direct.f - lumped.f).norm() < 1e-12);
    }

    #[test]
    fn composition_applies_in_order() {
        let (a, b) = (
            xf(),
            Xform {
                e: *Rotation3::from_euler_angles(0.1, 0.2, -0.3).matrix(),
                r: Vector3::new(-0.5, 0.3, 0.2),
            },
        );
        let m = Motion {
            w: Vector3::new(0.4, -1.0, 2.0),
            v: Vector3::new(-0.3, 0.9, 0.1),
        };
        let (two, one) = (b.motion(a.motion(m)), a.then(b).motion(m));
        assert!((two.w - one.w).norm() < 1e-12 && (two.v - one.v).norm() < 1e-12);
    }
}
