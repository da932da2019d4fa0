//! How the strip is cut into links: the discretisation of the finger (see models/README.md, "The
//! finger as a discretised strip").
//!
//! The strip is flexible except for two pieces of fixed physical size: the sensor pad's rigid
//! 12 mm casing and the tendon's anchor at the tip. The loads the wrap puts on the object change
//! fastest at those pieces' edges, so their size must not change with the discretisation: their
//! edges are joints at any number of links, and the uniform grid of `finger.segments` links cuts
//! only the flexible stretches between them.

use super::config::{BaseJoint, FingerConfig};

/// Half the sensor pad's casing length \[m\] (12 mm casing, paper Sec. II).
pub const PAD_HALF_LENGTH_M: f64 = 0.006;

/// Length of the rigid piece at the strip's tip that anchors the tendon \[m\]. A stated choice:
/// 10 mm, a tendon anchor block of about the strip's width; not published.
pub const TIP_LENGTH_M: f64 = 0.01;

/// One rigid link of the discretised strip.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Piece {
    /// Arc length of the piece's start from the strip's base \[m\].
    pub start_m: f64,
    /// Length of the piece \[m\].
    pub length_m: f64,
    /// Whether this piece is one of the fixed rigid pieces (pad casing, tip anchor) rather than a
    /// cut of the flexible strip.
    pub fixed: bool,
    /// Length of flexible strip the joint at the piece's start stands for \[m\]: half of each
    /// flexible neighbour (a joint between a flexible piece and a rigid one bends only for the
    /// flexible half). Per-joint stiffness, damping and armature are the per-length values
    /// divided by it.
    pub joint_span_m: f64,
}

/// The pieces of the strip, base to tip, for `f`: the uniform grid of `f.segments` links with the
/// pad casing and the tip anchor as single pieces, and grid points closer than half a link to a
/// piece's edge dropped (no slivers).
pub fn layout(f: &FingerConfig) -> Vec<Piece> {
    layout_with_pads(f, &[])
}

/// As [`layout`], with the casings of further pads centred at `extra_pads_m` \[m of arc\] as rigid
/// pieces too (a sensor array, `[array]`). Each further pad's casing is cut out of the grid as pad
/// 0's is; the finer base stretch still ends at pad 0's casing.
pub fn layout_with_pads(f: &FingerConfig, extra_pads_m: &[f64]) -> Vec<Piece> {
    let l = f.segment_length_m();
    let length = f.length_m;
    let casing = |centre: f64| (centre - PAD_HALF_LENGTH_M, centre + PAD_HALF_LENGTH_M);
    let pad = casing(f.pad_position_m);
    let pads: Vec<(f64, f64)> = std::iter::once(pad).chain(extra_pads_m.iter().map(|&c| casing(c))).collect();
    let tip = length - TIP_LENGTH_M.min(length / 4.0);
    let mut edges: Vec<f64> = pads.iter().flat_map(|&(a, b)| [a, b]).collect();
    edges.push(tip);
    let inside_fixed = |s: f64| pads.iter().any(|&(a, b)| s > a && s < b) || s > tip;
    // The base stretch (up to the pad's casing) on its finer grid from `fine_from_m` on, the rest
    // on the uniform one; a grid point closer than half its own link to a fixed edge is dropped, and
    // a coarse point closer than half a fine link to the fine grid's start (no slivers there either).
    let base_l = l / f64::from(f.base_refinement.max(1));
    let first_fine = (f.fine_from_m.max(0.0) / base_l - 1e-9).ceil().max(1.0) * base_l;
    let base_grid = (1..)
        .map(|i| f64::from(i) * base_l)
        .take_while(|&s| s < pad.0)
        .filter(|&s| s >= first_fine - 1e-12)
        .map(|s| (s, base_l));
    let rest_grid =
        (1..f.segments).map(|i| (f64::from(i) * l, l)).filter(|&(s, _)| s > pad.0 || s < first_fine - base_l / 2.0);
    let mut cuts: Vec<f64> = base_grid
        .chain(rest_grid)
        .filter(|&(s, h)| !inside_fixed(s) && edges.iter().all(|e| (s - e).abs() >= h / 2.0 - 1e-12))
        .map(|(s, _)| s)
        .collect();
    // Two casings end to end share an edge: one cut.
    for e in edges {
        if !cuts.iter().any(|c| (c - e).abs() < 1e-12) {
            cuts.push(e);
        }
    }
    cuts.push(0.0);
    cuts.sort_by(f64::total_cmp);
    let fixed = |start: f64| pads.iter().any(|&(a, _)| (start - a).abs() < 1e-12) || (start - tip).abs() < 1e-12;
    let mut pieces: Vec<Piece> = cuts
        .iter()
        .enumerate()
        .map(|(k, &start)| {
            let end = cuts.get(k + 1).copied().unwrap_or(length);
            Piece { start_m: start, length_m: end - start, fixed: fixed(start), joint_span_m: 0.0 }
        })
        .collect();
    let flex = |p: &Piece| if p.fixed { 0.0 } else { p.length_m / 2.0 };
    // The clamp: no strip lies before the base's joint, so the Hencky chain gives it the first
    // link's half alone; `WholeLink` counts that half twice (`finger.base_joint`).
    let at_clamp = match f.base_joint {
        BaseJoint::WholeLink => flex(&pieces[0]),
        BaseJoint::HalfLink => 0.0,
    };
    for k in 0..pieces.len() {
        let before = if k == 0 { at_clamp } else { flex(&pieces[k - 1]) };
        pieces[k].joint_span_m = before + flex(&pieces[k]);
    }
    pieces
}

/// The piece that carries the pad centred at `centre_m` \[m of arc\] (its casing's piece).
pub fn pad_piece(pieces: &[Piece], centre_m: f64) -> usize {
    pieces.iter().position(|p| p.fixed && (p.start_m - (centre_m - PAD_HALF_LENGTH_M)).abs() < 1e-12).unwrap_or(0)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_fixed_pieces_are_the_same_at_any_number_of_links() {
        for n in [8, 16, 32, 64, 128] {
            let f = FingerConfig { segments: n, base_refinement: 1, ..FingerConfig::default() };
            let pieces = layout(&f);
            let total: f64 = pieces.iter().map(|p| p.length_m).sum();
            assert!((total - f.length_m).abs() < 1e-12, "{n}: {total}");
            let fixed: Vec<(f64, f64)> = pieces.iter().filter(|p| p.fixed).map(|p| (p.start_m, p.length_m)).collect();
            assert_eq!(fixed.len(), 2, "{n}");
            assert!((fixed[0].1 - 2.0 * PAD_HALF_LENGTH_M).abs() < 1e-12);
            assert!((fixed[0].0 - (f.pad_position_m - PAD_HALF_LENGTH_M)).abs() < 1e-12);
            assert!((fixed[1].1 - TIP_LENGTH_M).abs() < 1e-12);
            let l = f.segment_length_m();
            for p in pieces.iter().filter(|p| !p.fixed) {
                assert!(p.length_m >= l / 2.0 - 1e-12 && p.length_m < 1.5 * l + 1e-12, "{n}: {p:?}");
            }
        }
    }

    #[test]
    fn a_refined_base_cuts_only_the_stretch_before_the_pad_finer() {
        let uniform = layout(&FingerConfig { base_refinement: 1, ..FingerConfig::default() });
        let f = FingerConfig { base_refinement: 4, ..FingerConfig::default() };
        let refined = layout(&f);
        let pad_start = f.pad_position_m - PAD_HALF_LENGTH_M;
        let (l, h) = (f.segment_length_m(), f.segment_length_m() / 4.0);
        // The pieces from the pad on (the pad's own joint span counts half its finer neighbour).
        let after_pad = |p: &[Piece]| {
            p.iter()
                .filter(|x| x.start_m >= pad_start - 1e-12)
                .map(|x| (x.start_m, x.length_m, x.fixed))
                .collect::<Vec<_>>()
        };
        assert_eq!(after_pad(&refined), after_pad(&uniform), "the pad and the strip beyond it are unchanged");
        let base: Vec<&Piece> = refined.iter().filter(|p| p.start_m < pad_start - 1e-12).collect();
        assert!(base.len() >= 4 * (pad_start / l).floor() as usize, "{} links before the pad", base.len());
        for p in &base {
            assert!(!p.fixed && p.length_m >= h / 2.0 - 1e-12 && p.length_m < 1.5 * h + 1e-12, "{p:?}");
        }
        let total: f64 = refined.iter().map(|p| p.length_m).sum();
        assert!((total - f.length_m).abs() < 1e-12);
    }

    #[test]
    fn a_fine_zone_keeps_the_coarse_links_below_it_and_the_fine_ones_from_it_to_the_pad() {
        let graded = FingerConfig::default();
        let l = graded.segment_length_m();
        let h = l / f64::from(graded.base_refinement);
        let pad_start = graded.pad_position_m - PAD_HALF_LENGTH_M;
        for fine_from in [l, 0.02, 0.03] {
            let f = FingerConfig { fine_from_m: fine_from, ..graded.clone() };
            let zoned = layout(&f);
            let total: f64 = zoned.iter().map(|p| p.length_m).sum();
            assert!((total - f.length_m).abs() < 1e-12, "{fine_from}");
            let first_fine = (fine_from / h - 1e-9).ceil() * h;
            for p in zoned.iter().filter(|p| !p.fixed && p.start_m < pad_start - 1e-12) {
                if p.start_m >= first_fine - 1e-12 {
                    assert!(p.length_m >= h / 2.0 - 1e-12 && p.length_m < 1.5 * h + 1e-12, "{fine_from}: {p:?}");
                } else {
                    assert!(p.length_m >= h / 2.0 - 1e-12 && p.length_m <= l + 1e-12, "{fine_from}: {p:?}");
                }
            }
            let from_zone = |p: &[Piece]| {
                p.iter()
                    .filter(|x| x.start_m >= first_fine - 1e-12)
                    .map(|x| (x.start_m, x.length_m))
                    .collect::<Vec<_>>()
            };
            assert_eq!(
                from_zone(&zoned),
                from_zone(&layout(&graded)),
                "{fine_from}: the zone and beyond are the graded finger's"
            );
            assert!(zoned.len() < layout(&graded).len(), "{fine_from}");
        }
        // One coarse link in place of the first eight fine ones at 20 mm: 21 bodies against 28.
        assert_eq!(layout(&FingerConfig { fine_from_m: l, ..graded }).len(), 21);
    }

    #[test]
    fn the_default_finger_has_the_converged_links_at_the_base_and_coarse_ones_beyond() {
        let f = FingerConfig::default();
        let pieces = layout(&f);
        let pad_start = f.pad_position_m - PAD_HALF_LENGTH_M;
        let (base, beyond): (Vec<&Piece>, Vec<&Piece>) =
            pieces.iter().filter(|p| !p.fixed).partition(|p| p.start_m < pad_start);
        // 2.5 mm up to the pad (a 56-link strip's links; the answers converge there with the
        // clamp's joint at half a link, models/README.md), 20 mm beyond it but for the pieces the
        // pad and the tip cut short: 28 bodies in all, against the uniform 64-link finger's 55.
        assert!(base.iter().all(|p| (p.length_m - 0.14 / 56.0).abs() < 0.6e-3), "{base:?}");
        assert!(beyond.iter().all(|p| p.length_m > 0.009 && p.length_m < 0.0201), "{beyond:?}");
        assert_eq!(pieces.len(), 28);
        let uniform = layout(&FingerConfig { segments: 64, base_refinement: 1, ..f });
        assert_eq!(uniform.len(), 55);
    }

    #[test]
    fn the_clamp_s_joint_stands_for_the_first_link_or_its_half_and_no_other_joint_moves() {
        let whole_link = FingerConfig { base_joint: BaseJoint::WholeLink, ..FingerConfig::default() };
        for f in [whole_link.clone(), FingerConfig { segments: 32, base_refinement: 1, ..whole_link }] {
            let whole = layout(&f);
            let half = layout(&FingerConfig { base_joint: BaseJoint::HalfLink, ..f.clone() });
            let first = whole[0].length_m;
            assert!((whole[0].joint_span_m - first).abs() < 1e-15, "{:?}", whole[0]);
            assert!((half[0].joint_span_m - first / 2.0).abs() < 1e-15, "{:?}", half[0]);
            // Every joint but the clamp's spans half of each flexible neighbour under both.
            assert_eq!(whole[1..], half[1..]);
            let (a, b) = (whole[1], whole[2]);
            assert!((b.joint_span_m - (a.length_m + b.length_m) / 2.0).abs() < 1e-15, "{b:?}");
        }
    }

    #[test]
    fn further_pads_are_rigid_pieces_and_pad_zeros_layout_is_unchanged_without_them() {
        let f = FingerConfig::default();
        assert_eq!(layout_with_pads(&f, &[]), layout(&f));
        let pieces = layout_with_pads(&f, &[0.03, 0.09]);
        for centre in [f.pad_position_m, 0.03, 0.09] {
            let p = pieces[pad_piece(&pieces, centre)];
            assert!(p.fixed && (p.length_m - 2.0 * PAD_HALF_LENGTH_M).abs() < 1e-12, "{centre}: {p:?}");
        }
        assert_eq!(pieces.iter().filter(|p| p.fixed).count(), 4);
        let total: f64 = pieces.iter().map(|p| p.length_m).sum();
        assert!((total - f.length_m).abs() < 1e-12);
        assert!(pieces.iter().all(|p| p.length_m > 1e-4), "no slivers: {pieces:?}");
    }
}
