//! The contact patch under the pin: a Cartesian grid on the pin face, blended into the
//! disc's polar grid, refined into tied contact layers on request.

use super::SizeRule;
use squeal_fe::Mesh;

/// The contact patch: the pin face's Cartesian grid `xs x ys` (sliding direction x,
/// radius y), which the disc mesh reproduces exactly under the pin.
pub(super) struct Patch {
    /// Grid lines along x (m), increasing.
    pub(super) xs: Vec<f64>,
    /// Grid lines along y (m), increasing.
    pub(super) ys: Vec<f64>,
    /// Centre radius (m).
    pub(super) yc: f64,
    /// Grid step (m).
    pub(super) step: f64,
}

/// The grid lines `(xs, ys)` of a face's nodes: their distinct x and y (to `1e-9` of the
/// face size), checked to form a full tensor grid with one node at each intersection.
pub(super) fn face_grid(
    mesh: &Mesh,
    face: &[usize],
) -> std::result::Result<(Vec<f64>, Vec<f64>), String> {
    let pts: Vec<[f64; 3]> = face.iter().map(|&n| mesh.nodes[n]).collect();
    let extent = |a: usize| {
        let (lo, hi) = pts
            .iter()
            .fold((f64::INFINITY, f64::NEG_INFINITY), |(l, h), p| {
                (l.min(p[a]), h.max(p[a]))
            });
        hi - lo
    };
    let tol = 1e-9 * extent(0).max(extent(1));
    let lines = |a: usize| {
        let mut v: Vec<f64> = pts.iter().map(|p| p[a]).collect();
        v.sort_by(f64::total_cmp);
        let mut out: Vec<f64> = Vec::new();
        for x in v {
            if out.last().is_none_or(|&l| x - l > tol) {
                out.push(x);
            }
        }
        out
    };
    let (xs, ys) = (lines(0), lines(1));
    let find = |v: &[f64], x: f64| v.iter().position(|&l| (l - x).abs() <= tol);
    let mut hit = vec![0usize; xs.len() * ys.len()];
    for p in &pts {
        if let (Some(i), Some(j)) = (find(&xs, p[0]), find(&ys, p[1])) {
            hit[j * xs.len() + i] += 1;
        }
    }
    let empty = hit.iter().filter(|&&h| h == 0).count();
    let doubled = hit.iter().filter(|&&h| h > 1).count();
    if xs.len() < 2 || ys.len() < 2 || empty > 0 || doubled > 0 {
        return Err(format!(
            "its {} nodes do not form a full tensor grid in (x, y): {} x-lines x {} y-lines, \
             {empty} intersections without a node, {doubled} with several; contact zones \
             need a grid (at least 2 x 2)",
            pts.len(),
            xs.len(),
            ys.len()
        ));
    }
    Ok((xs, ys))
}

impl Patch {
    /// The patch of an imported pin face with grid lines `xs`, `ys` (see [`face_grid`]).
    pub(super) fn from_grid(xs: Vec<f64>, ys: Vec<f64>) -> Self {
        let step = xs
            .windows(2)
            .chain(ys.windows(2))
            .map(|w| w[1] - w[0])
            .fold(f64::INFINITY, f64::min);
        let yc = 0.5 * (ys[0] + ys[ys.len() - 1]);
        Patch { xs, ys, yc, step }
    }

    pub(super) fn new(p: &crate::Pin, n: usize) -> Self {
        let (a, b, yc) = (p.size_x_m, p.size_y_m, p.center_radius_m);
        Patch {
            xs: squeal_fe::mesh::linspace(-a / 2.0, a / 2.0, n),
            ys: squeal_fe::mesh::linspace(yc - b / 2.0, yc + b / 2.0, n),
            yc,
            step: a.min(b) / n as f64,
        }
    }

    /// The patch with lines every `r.element_m` or less inside `r.region_m` (face
    /// coordinates), widened outward to this patch's lines; this patch's lines elsewhere.
    pub(super) fn refined(&self, r: &crate::ContactRefinement) -> Patch {
        let lines = |v: &[f64], lo: f64, hi: f64| {
            let tol = 1e-9 * (v[v.len() - 1] - v[0]);
            let a = v.iter().rposition(|&x| x <= lo + tol).unwrap_or(0);
            let b = v.iter().position(|&x| x >= hi - tol).unwrap_or(v.len() - 1);
            let n = ((v[b] - v[a]) / r.element_m - 1e-9).ceil().max(1.0) as usize;
            let mut out = v[..a].to_vec();
            out.extend(squeal_fe::mesh::linspace(v[a], v[b], n));
            out.extend_from_slice(&v[b + 1..]);
            out
        };
        let [x0, y0, a, b] = r.region_m;
        let (cx, cy) = (self.xs[0], self.ys[0]);
        let mut p = Patch::from_grid(
            lines(&self.xs, cx + x0, cx + x0 + a),
            lines(&self.ys, cy + y0, cy + y0 + b),
        );
        p.yc = self.yc;
        p
    }

    /// Half the angle the patch spans at its centre radius.
    pub(super) fn half_angle(&self) -> f64 {
        self.xs[self.xs.len() - 1] / self.yc
    }

    /// Angular grid: the patch lines at `theta = pi/2 - x/yc`, graded by `ratio` up to
    /// `dtheta` around the rest of the turn. Increasing, less than one turn.
    pub(super) fn thetas(&self, dtheta: f64, ratio: f64) -> Vec<f64> {
        let c = std::f64::consts::FRAC_PI_2;
        let mut th: Vec<f64> = self.xs.iter().rev().map(|x| c - x / self.yc).collect();
        let span = 2.0 * std::f64::consts::PI - 2.0 * self.half_angle();
        let half = squeal_fe::mesh::graded_steps(span / 2.0, self.step / self.yc, dtheta, ratio);
        let mut steps = half.clone();
        steps.extend(half.iter().rev());
        let mut t = th[th.len() - 1];
        for st in &steps[..steps.len() - 1] {
            t += st;
            th.push(t);
        }
        th
    }

    /// The in-plane map: Cartesian `(-yc phi, r)` on the patch (`phi = theta - pi/2`),
    /// polar far from it, a smooth blend over one patch size around it that vanishes
    /// before the hat wall and the outer edge (which stays a true circle).
    pub(super) fn blend(&self, r_wall: f64, r_out: f64) -> Blend {
        let (r0, r1) = (self.ys[0], self.ys[self.ys.len() - 1]);
        let b = r1 - r0;
        Blend {
            r0,
            r1,
            yc: self.yc,
            half: self.half_angle(),
            dr_in: b.min(0.8 * (r0 - r_wall)),
            dr_out: b.min(0.8 * (r_out - r1)),
            dphi: (2.0 * self.half_angle()).min(0.5 * (std::f64::consts::PI - self.half_angle())),
        }
    }
}

/// See [`Patch::blend`].
pub(super) struct Blend {
    r0: f64,
    r1: f64,
    pub(super) yc: f64,
    half: f64,
    dr_in: f64,
    dr_out: f64,
    dphi: f64,
}

impl Blend {
    pub(super) fn map(&self, r: f64, th: f64) -> [f64; 2] {
        let polar = [r * th.cos(), r * th.sin()];
        let mut phi = th - std::f64::consts::FRAC_PI_2;
        while phi > std::f64::consts::PI {
            phi -= 2.0 * std::f64::consts::PI;
        }
        while phi <= -std::f64::consts::PI {
            phi += 2.0 * std::f64::consts::PI;
        }
        let tr = if r < self.r0 {
            (self.r0 - r) / self.dr_in
        } else if r > self.r1 {
            (r - self.r1) / self.dr_out
        } else {
            0.0
        };
        let tp = ((phi.abs() - self.half) / self.dphi).max(0.0);
        // smooth step: 1 at t <= 0, 0 at t >= 1, zero slope at both ends
        let step = |t: f64| {
            if t <= 1e-12 {
                1.0
            } else if t >= 1.0 {
                0.0
            } else {
                1.0 - t * t * (3.0 - 2.0 * t)
            }
        };
        let w = step(tr) * step(tp);
        if w == 1.0 {
            [-self.yc * phi, r]
        } else if w == 0.0 {
            polar
        } else {
            [
                w * (-self.yc * phi) + (1.0 - w) * polar[0],
                w * r + (1.0 - w) * polar[1],
            ]
        }
    }
}

/// Appends the contact layer `layer` of `body` (node sets `{body}_layer.*`) and ties its
/// face `tied` to the face `master` of the coarse body (`{body}.{master}`, on the coarse
/// patch grid); returns the ties and the layer's size rule (`nl` element layers).
#[allow(clippy::too_many_arguments)]
pub(super) fn contact_layer(
    mesh: &mut Mesh,
    layer: &Mesh,
    body: &str,
    tied: &str,
    master: &str,
    coarse: &Patch,
    fine: &Patch,
    nl: usize,
) -> std::result::Result<(Vec<squeal_fe::Tie>, SizeRule), String> {
    mesh.append(layer, &format!("{body}_layer."), None);
    let ties = squeal_fe::mesh::face_ties(
        mesh,
        mesh.node_set(&format!("{body}_layer.{tied}"))?,
        mesh.node_set(&format!("{body}.{master}"))?,
        &coarse.xs,
        &coarse.ys,
    )
    .map_err(|m| format!("{body} contact layer: {m}"))?;
    let rule = SizeRule {
        body: format!("{body} contact layer"),
        wavelength_m: f64::NAN,
        element_size_m: fine.step,
        divisions: [fine.xs.len() - 1, fine.ys.len() - 1, nl],
    };
    Ok((ties, rule))
}
