//! A Cholesky factorisation of the joint-space inertia in place, with no
//! allocation per call (it is factored four or five times per step), that
//! skips the zeros a branched arm's inertia has.
//!
//! Two joints on different branches (a left and a right arm) do not couple:
//! their entry of M is zero. Eliminated leaves first, a tree's factor has
//! no fill: column k of L is non-zero only at k's ancestors (Featherstone
//! 2008, §6.5). So the factor is made in an elimination order (children
//! before parents) and each column keeps the rows it can reach; a serial
//! arm has all of them, a humanoid's 30 joints a tenth of the dense work.
//! The order and the rows are fixed when the arm is built; the matrix in
//! and the vectors out stay in the joints' own order.

/// An n × n matrix (row-major, the joints' order) and, after `factor`, its
/// factor L L̃ᵀ = P M Pᵀ in the elimination order.
#[derive(Debug, Clone)]
pub(super) struct Cholesky {
    n: usize,
    a: Vec<f64>,
    /// The factor, row-major in the elimination order (lower part).
    l: Vec<f64>,
    /// 1 / L_kk: the solves multiply (a division is ten times a product).
    inv_diag: Vec<f64>,
    /// Elimination position → joint.
    order: Vec<usize>,
    /// Joint → elimination position.
    pos: Vec<usize>,
    /// Per position k: the later positions where column k of L may be
    /// non-zero, ascending (fill included).
    below: Vec<Vec<usize>>,
    /// Per joint: its group of joints that couple, directly or through
    /// others (the fixed root's subtrees). M and M⁻¹ are block diagonal
    /// over the groups.
    group: Vec<usize>,
}

impl Cholesky {
    /// A dense n × n factorisation in the joints' order.
    #[cfg(test)]
    pub(super) fn new(n: usize) -> Self {
        Self::with_structure((0..n).collect(), |_, _| true)
    }

    /// A factorisation that eliminates the joints in `order` (each joint
    /// once) where M's entry (i, j) can be non-zero only when
    /// `coupled(i, j)`.
    pub(super) fn with_structure(
        order: Vec<usize>,
        coupled: impl Fn(usize, usize) -> bool,
    ) -> Self {
        let n = order.len();
        let mut pos = vec![0; n];
        for (k, &j) in order.iter().enumerate() {
            pos[j] = k;
        }
        // Symbolic elimination: removing k couples every pair it reaches.
        let mut reach = vec![false; n * n];
        for i in 0..n {
            for k in 0..i {
                let c = coupled(order[i], order[k]) || coupled(order[k], order[i]);
                reach[i * n + k] = c;
            }
        }
        // Groups: joints joined by a chain of couplings share a label.
        let mut group: Vec<usize> = (0..n).collect();
        for i in 0..n {
            for j in 0..i {
                let (a, b) = (group[i], group[j]);
                if a != b && (coupled(i, j) || coupled(j, i)) {
                    group.iter_mut().filter(|g| **g == a).for_each(|g| *g = b);
                }
            }
        }
        let mut below = Vec::with_capacity(n);
        for k in 0..n {
            let rows: Vec<usize> = (k + 1..n).filter(|&i| reach[i * n + k]).collect();
            for (x, &i) in rows.iter().enumerate() {
                for &j in &rows[..x] {
                    reach[i * n + j] = true;
                }
            }
            below.push(rows);
        }
        Self {
            n,
            a: vec![0.0; n * n],
            l: vec![0.0; n * n],
            inv_diag: vec![0.0; n],
            order,
            pos,
            below,
            group,
        }
    }

    /// The group of joint `j`: joints of different groups do not couple.
    pub(super) fn group(&self, j: usize) -> usize {
        self.group[j]
    }

    /// The matrix to fill before `factor` (row-major, the joints' order).
    pub(super) fn matrix_mut(&mut self) -> &mut [f64] {
        &mut self.a
    }

    /// The matrix as filled (`factor` leaves it).
    pub(super) fn matrix(&self) -> &[f64] {
        &self.a
    }

    /// Factors the matrix; Err(joint) where it is not positive definite (or
    /// NaN): the first joint, in the joints' order, whose inertia about its
    /// axis the joints before it already account for (see
    /// [`Self::first_singular_in_order`]).
    pub(super) fn factor(&mut self) -> Result<(), usize> {
        let n = self.n;
        for (k, &jk) in self.order.iter().enumerate() {
            self.l[k * n + k] = self.a[jk * n + jk];
            for &i in &self.below[k] {
                self.l[i * n + k] = self.a[self.order[i] * n + jk];
            }
        }
        let l = &mut self.l;
        for k in 0..n {
            let d = l[k * n + k];
            // Not positive, or NaN.
            if d.is_nan() || d <= 0.0 {
                return Err(self.first_singular_in_order().unwrap_or(self.order[k]));
            }
            let d = d.sqrt();
            l[k * n + k] = d;
            let inv = d.recip();
            self.inv_diag[k] = inv;
            let rows = &self.below[k];
            for &i in rows {
                l[i * n + k] *= inv;
            }
            // The Schur complement on the rows k reaches.
            for (x, &i) in rows.iter().enumerate() {
                let lik = l[i * n + k];
                for &j in &rows[..=x] {
                    l[i * n + j] -= lik * l[j * n + k];
                }
            }
        }
        Ok(())
    }

    /// Where a matrix that failed is singular, named as a dense factor in
    /// the joints' (tree) order names it: leaves first, the failing pivot
    /// can be a parent whose own links have mass, while root first it is
    /// the joint that adds nothing. Only a finite matrix is searched (a
    /// blown-up state has nothing to name); this runs only on failure.
    fn first_singular_in_order(&self) -> Option<usize> {
        let n = self.n;
        if self.a.iter().any(|x| !x.is_finite()) {
            return None;
        }
        let mut l = self.a.clone();
        for j in 0..n {
            let d = l[j * n + j] - (0..j).map(|k| l[j * n + k] * l[j * n + k]).sum::<f64>();
            if d.is_nan() || d <= 0.0 {
                return Some(j);
            }
            let d = d.sqrt();
            l[j * n + j] = d;
            for i in j + 1..n {
                let s = l[i * n + j] - (0..j).map(|k| l[i * n + k] * l[j * n + k]).sum::<f64>();
                l[i * n + j] = s / d;
            }
        }
        None
    }

    /// x = M⁻¹ b in place, after `factor`.
    pub(super) fn solve(&self, b: &mut [f64]) {
        self.forward(b, 0);
        self.backward(b);
    }

    /// b ← L⁻¹ P b (kept in the joints' slots), where P b is zero before
    /// position `from`.
    fn forward(&self, b: &mut [f64], from: usize) {
        let (n, l) = (self.n, &self.l);
        for k in from..self.n {
            let jk = self.order[k];
            if b[jk] == 0.0 {
                continue;
            }
            let y = b[jk] * self.inv_diag[k];
            b[jk] = y;
            for &i in &self.below[k] {
                b[self.order[i]] -= l[i * n + k] * y;
            }
        }
    }

    /// b ← Pᵀ L⁻ᵀ b, after [`Self::forward`].
    fn backward(&self, b: &mut [f64]) {
        let (n, l) = (self.n, &self.l);
        for k in (0..n).rev() {
            let s = self.below[k].iter().fold(b[self.order[k]], |s, &i| {
                s - l[i * n + k] * b[self.order[i]]
            });
            b[self.order[k]] = s * self.inv_diag[k];
        }
    }

    /// (M⁻¹)_jj = ‖L⁻¹ P e_j‖², after `factor`; `x` is scratch of length n.
    /// P e_j is zero before j's position, so only the rows j reaches work.
    pub(super) fn inverse_diagonal(&self, j: usize, x: &mut [f64]) -> f64 {
        x.iter_mut().for_each(|v| *v = 0.0);
        x[j] = 1.0;
        self.forward(x, self.pos[j]);
        x.iter().map(|v| v * v).sum()
    }

    /// M⁻¹'s columns `cols` into `out` (row-major n × n; symmetric, so
    /// column j is row j; other rows untouched), after `factor`: each
    /// column's forward solve starts at its joint's position.
    pub(super) fn inverse_columns(&self, cols: &[usize], out: &mut [f64]) {
        let n = self.n;
        for &j in cols {
            let x = &mut out[j * n..(j + 1) * n];
            x.iter_mut().for_each(|v| *v = 0.0);
            x[j] = 1.0;
            self.forward(x, self.pos[j]);
            self.backward(x);
        }
    }

    /// Takes `other`'s factor (same structure), keeping this one's buffers.
    pub(super) fn copy_factor(&mut self, other: &Self) {
        self.l.copy_from_slice(&other.l);
        self.inv_diag.copy_from_slice(&other.inv_diag);
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn factored(n: usize, a: &[f64]) -> Cholesky {
        let mut c = Cholesky::new(n);
        c.matrix_mut().copy_from_slice(a);
        c.factor().unwrap_or_else(|row| panic!("row {row}"));
        c
    }

    #[test]
    fn solves_a_spd_system_and_refuses_a_singular_one() {
        let a = [4.0, 1.0, 0.5, 1.0, 3.0, 0.2, 0.5, 0.2, 2.0];
        let c = factored(3, &a);
        let mut inv = [0.0; 9];
        c.inverse_columns(&[0, 1, 2], &mut inv);
        let mut x = [0.0; 3];
        for j in 0..3 {
            let mut col = [0.0; 3];
            col[j] = 1.0;
            c.solve(&mut col);
            for i in 0..3 {
                assert!((inv[j * 3 + i] - col[i]).abs() < 1e-15, "{inv:?}");
            }
            assert!((c.inverse_diagonal(j, &mut x) - col[j]).abs() < 1e-15);
        }
        let mut x = [1.0, -2.0, 0.5];
        c.solve(&mut x);
        for i in 0..3 {
            let ax: f64 = (0..3).map(|k| a[i * 3 + k] * x[k]).sum();
            assert!((ax - [1.0, -2.0, 0.5][i]).abs() < 1e-14);
        }
        let mut c = Cholesky::new(3);
        c.matrix_mut()
            .copy_from_slice(&[1.0, 1.0, 0.0, 1.0, 1.0, 0.0, 0.0, 0.0, 1.0]);
        assert_eq!(c.factor(), Err(1));
        c.matrix_mut()[0] = f64::NAN;
        assert_eq!(c.factor(), Err(0));
    }

    /// Five joints: 0 the root; 1 → 2 one branch, 3 → 4 the other; with
    /// `cross`, joints 2 and 4 couple too (a mimic across the branches).
    fn branched(cross: bool) -> impl Fn(usize, usize) -> bool {
        let parent = [None, Some(0), Some(1), Some(0), Some(3)];
        let ancestor = move |a: usize, mut b: usize| loop {
            if a == b {
                return true;
            }
            match parent[b] {
                Some(p) => b = p,
                None => return false,
            }
        };
        move |i, j| {
            ancestor(i, j) || ancestor(j, i) || (cross && ((i, j) == (2, 4) || (i, j) == (4, 2)))
        }
    }

    /// A positive definite matrix on the `coupled` pattern, its dense
    /// factor, and the leaves-first one (factored).
    fn both_factors(
        coupled: impl Fn(usize, usize) -> bool + Copy,
    ) -> (Vec<f64>, Cholesky, Cholesky) {
        let n = 5;
        let mut a = vec![0.0; n * n];
        for i in 0..n {
            for j in 0..n {
                if coupled(i, j) {
                    a[i * n + j] = if i == j {
                        6.0 + i as f64
                    } else {
                        0.5 / (1 + i + j) as f64
                    };
                }
            }
        }
        let mut tree = Cholesky::with_structure(vec![4, 2, 3, 1, 0], coupled);
        tree.matrix_mut().copy_from_slice(&a);
        tree.factor().unwrap_or_else(|row| panic!("row {row}"));
        (a.clone(), factored(n, &a), tree)
    }

    /// M⁻¹ and a solve from both factors agree.
    fn assert_same(tree: &Cholesky, dense: &Cholesky) {
        let n = 5;
        let (mut got, mut want) = (vec![0.0; n * n], vec![0.0; n * n]);
        let all: Vec<usize> = (0..n).collect();
        tree.inverse_columns(&all, &mut got);
        dense.inverse_columns(&all, &mut want);
        for (g, w) in got.iter().zip(&want) {
            assert!((g - w).abs() < 1e-14, "{got:?} vs {want:?}");
        }
        let (mut b, mut c) = ([1.0, -2.0, 0.5, 3.0, 0.25], [1.0, -2.0, 0.5, 3.0, 0.25]);
        tree.solve(&mut b);
        dense.solve(&mut c);
        for (x, y) in b.iter().zip(&c) {
            assert!((x - y).abs() < 1e-14);
        }
    }

    /// A branched arm's inertia, eliminated leaves first with only the
    /// ancestors' rows, solves as the dense factor does, and a singular
    /// pivot names its joint in the joints' order.
    #[test]
    fn a_tree_eliminated_leaves_first_solves_as_the_dense_factor() {
        let n = 5;
        let coupled = branched(false);
        let (a, dense, mut tree) = both_factors(&coupled);
        // One group: everything hangs from joint 0.
        assert!((0..n).all(|j| tree.group(j) == tree.group(0)));
        // No fill: every column reaches only its joint's ancestors.
        let reached: usize = tree.below.iter().map(Vec::len).sum();
        assert_eq!(reached, 4 + 2);
        assert_same(&tree, &dense);
        // Joint 2 massless: its pivot is the first not positive.
        tree.matrix_mut()[2 * n + 2] = 0.0;
        assert_eq!(tree.factor(), Err(2));
        // Joints 3 and 4 turn together (a coaxial pair with nothing
        // between): leaves first, joint 3's pivot fails; the joint named is
        // the one that adds nothing in tree order, joint 4, as before.
        tree.matrix_mut().copy_from_slice(&a);
        for (i, j) in [(3, 3), (3, 4), (4, 3), (4, 4)] {
            tree.matrix_mut()[i * n + j] = 1.0;
        }
        assert_eq!(tree.factor(), Err(4));
    }

    /// A coupling across branches (a mimic joint on one that follows the
    /// other's joint) makes fill; the factor takes it in and still solves
    /// as the dense one does.
    #[test]
    fn a_coupling_across_branches_is_filled_in() {
        let coupled = branched(true);
        let (_, dense, tree) = both_factors(&coupled);
        // The tree's 6, the cross coupling, and two of fill: eliminating
        // joint 4 couples 2 with 3, then eliminating 2 couples 3 with 1.
        let reached: usize = tree.below.iter().map(Vec::len).sum();
        assert_eq!(reached, 6 + 1 + 2);
        assert_same(&tree, &dense);
    }
}
