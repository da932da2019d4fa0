//! A produce item: a deformable fruit or vegetable as a MuJoCo flex, read from its model file and
//! nowhere else.
//!
//! A produce file (`models/objects/cherry_tomato.xml`, ...) is a standalone MJCF that keeps one
//! contract, checked when a run starts:
//!
//! - one `<flexcomp name="produce">` of dimension 3 with interpolated degrees of freedom
//!   (`dof="trilinear"` or `"quadratic"`), of `type="ellipsoid"` (a fruit; a bunch of leaves is
//!   a tall spheroid), centred on the file's origin; its `mass`, `count` and `spacing` give the
//!   item's mass and size, and its `<contact>` its friction against the finger;
//! - its `<elasticity>` gives only the `damping`: the flex's `young` and `poisson` are set when
//!   the scene is built from the figures below, so that a value is written once; its `<contact>`
//!   gives the friction and the collision bits, not `solref` or `solimp`: the contact's softness is
//!   the cell's (`physics.contact_solimp`) with the stiffness of the plate-compression calibration
//!   ([`super::plates`]);
//! - `<custom>` numerics with the item's published properties: `produce_modulus_pa` (the flesh's
//!   apparent modulus E, Hertz's), `produce_poisson`, `produce_bruise_pa` (the contact pressure
//!   above which the tissue bruises) and, for an item that can be harvested, `produce_detach_n`
//!   (the force at which its stem lets go); `produce_wrap_m` (optional, 0 by default) puts the
//!   start of the finger's wrap that far above the item's centre.
//!
//! `[produce]` in a scenario overrides the properties within their literature range and the
//! flex's grid and degrees of freedom ([`super::produce_config::ProduceConfig`]).

use super::PhysicsError;
use super::produce_config::{Dof, ProduceConfig, grid_fault, modulus_fault, poisson_fault};
use mujoco_rs::mujoco_c::_mjtObjBase;
use mujoco_rs::prelude::{MjData, MjModel};

/// The flexcomp's name every produce file uses.
pub const FLEX_NAME: &str = "produce";

/// The item's published properties (the file's, or the scenario's overrides).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ProduceProperties {
    /// The flesh's apparent elastic modulus E \[Pa\] (Hertz's, as the ASAE S368 compression test
    /// defines it).
    pub modulus_pa: f64,
    /// Poisson's ratio of the flesh \[-\].
    pub poisson: f64,
    /// Contact pressure above which the tissue bruises \[Pa\].
    pub bruise_pa: f64,
    /// Force at which the stem lets go of the plant \[N\] (`None`: the file gives none, and the
    /// item cannot be harvested).
    pub detach_n: Option<f64>,
}

/// A produce item: its document and the figures the scene places and judges it by.
#[derive(Debug, Clone, PartialEq)]
pub struct ProduceItem {
    /// Where the text came from (a shipped item's name or a file), for messages.
    pub source: String,
    /// The MJCF document, the scenario's overrides applied (grid, degrees of freedom, mass,
    /// friction), the flex's `young` and `poisson` not yet set ([`ProduceItem::document`]).
    pub mjcf: String,
    /// Mass of the flex \[kg\].
    pub mass_kg: f64,
    /// Semi-axes of the undeformed item along x, y and z \[m\] (the collision surface's, the
    /// flex's radius included).
    pub radii_m: [f64; 3],
    /// Height of the wrap's start above the item's centre \[m\].
    pub wrap_m: f64,
    /// The published properties, overrides applied.
    pub properties: ProduceProperties,
    /// The flex's degrees of freedom.
    pub dof: Dof,
    /// Points per axis of the flex's grid.
    pub count: [u32; 3],
    /// The flex's friction against the finger (sliding) \[-\].
    pub friction: f64,
}

/// Whether `mjcf` is a produce file (it holds a flexcomp named [`FLEX_NAME`]).
pub fn is_produce(mjcf: &str) -> bool {
    flexcomp_span(mjcf).is_some()
}

/// Byte range of the `<flexcomp ...>` opening tag named [`FLEX_NAME`].
fn flexcomp_span(text: &str) -> Option<(usize, usize)> {
    let mut from = 0;
    while let Some(at) = text[from..].find("<flexcomp") {
        let start = from + at;
        let end = start + text[start..].find('>')?;
        if attr(&text[start..end], "name").as_deref() == Some(FLEX_NAME) {
            return Some((start, end));
        }
        from = end;
    }
    None
}

/// Byte range of the first `<child .../>` element inside the flexcomp (its opening tag's end to
/// `</flexcomp>`).
fn child_span(text: &str, child: &str) -> Option<(usize, usize)> {
    let (_, open_end) = flexcomp_span(text)?;
    let close = open_end + text[open_end..].find("</flexcomp>")?;
    let at = open_end + text[open_end..close].find(&format!("<{child}"))?;
    let end = at + text[at..close].find('>')?;
    Some((at, end))
}

/// The value of attribute `name` in the tag text `tag` (`<x a="1" b="2"`).
pub(crate) fn attr(tag: &str, name: &str) -> Option<String> {
    let key = format!(" {name}=\"");
    let at = tag.find(&key)? + key.len();
    let len = tag[at..].find('"')?;
    Some(tag[at..at + len].to_string())
}

/// `tag` with attribute `name` set to `value` (replaced, or added before the tag's end).
pub(crate) fn with_attr(tag: &str, name: &str, value: &str) -> String {
    let key = format!(" {name}=\"");
    match tag.find(&key) {
        Some(at) => {
            let start = at + key.len();
            let len = tag[start..].find('"').unwrap_or(0);
            format!("{}{}{}", &tag[..start], value, &tag[start + len..])
        }
        None => {
            // Before a self-closing `/`, if the tag has one.
            let trimmed = tag.trim_end();
            match trimmed.strip_suffix('/') {
                Some(head) => format!("{} {name}=\"{value}\"/", head.trim_end()),
                None => format!("{trimmed} {name}=\"{value}\""),
            }
        }
    }
}

/// `text` with the tag at `span` replaced by `edit(tag)`.
fn edit_span(text: &str, span: (usize, usize), edit: impl FnOnce(&str) -> String) -> String {
    format!("{}{}{}", &text[..span.0], edit(&text[span.0..span.1]), &text[span.1..])
}

/// A custom numeric of the compiled model, by name.
fn numeric(m: &MjModel, name: &str) -> Option<f64> {
    let id = m.name_to_id(_mjtObjBase::mjOBJ_NUMERIC, name)?;
    let adr = m.numeric_adr()[id] as usize;
    (m.numeric_size()[id] > 0).then(|| m.numeric_data()[adr])
}

impl ProduceItem {
    /// Reads a produce file (`source` names it in messages): checks the contract, compiles it on
    /// its own and reads the mass, size and properties.
    pub fn read(source: &str, mjcf: &str) -> Result<ProduceItem, PhysicsError> {
        let broken = |what: String| PhysicsError::Object { file: source.to_string(), what };
        let (open, end) = flexcomp_span(mjcf).ok_or_else(|| broken(format!("no <flexcomp name=\"{FLEX_NAME}\">")))?;
        let tag = &mjcf[open..end];
        let dof = match attr(tag, "dof").as_deref() {
            Some("trilinear") => Dof::Trilinear,
            Some("quadratic") => Dof::Quadratic,
            other => {
                return Err(broken(format!(
                    "the flexcomp needs dof=\"trilinear\" or \"quadratic\" (interpolated degrees of freedom), got {other:?}"
                )));
            }
        };
        if attr(tag, "type").as_deref() != Some("ellipsoid") {
            return Err(broken(format!("the flexcomp must be of type \"ellipsoid\", got {:?}", attr(tag, "type"))));
        }
        if attr(tag, "dim").as_deref() != Some("3") {
            return Err(broken("the flexcomp needs dim=\"3\" (a solid)".into()));
        }
        let count = attr(tag, "count")
            .and_then(|c| {
                let v: Vec<u32> = c.split_whitespace().filter_map(|n| n.parse().ok()).collect();
                <[u32; 3]>::try_from(v).ok()
            })
            .ok_or_else(|| broken("the flexcomp needs count=\"nx ny nz\"".into()))?;
        if let Some(fault) = grid_fault(count) {
            return Err(broken(format!("flexcomp count: {fault}")));
        }
        let elasticity = child_span(mjcf, "elasticity")
            .ok_or_else(|| broken("the flexcomp needs an <elasticity damping=\"...\"/>".into()))?;
        for set in ["young", "poisson"] {
            if attr(&mjcf[elasticity.0..elasticity.1], set).is_some() {
                return Err(broken(format!(
                    "<elasticity> must not set `{set}`: it comes from the custom numerics produce_modulus_pa and produce_poisson and the plate calibration"
                )));
            }
        }
        let contact = child_span(mjcf, "contact")
            .ok_or_else(|| broken("the flexcomp needs a <contact friction=\"...\"/>".into()))?;
        for set in ["solref", "solimp"] {
            if attr(&mjcf[contact.0..contact.1], set).is_some() {
                return Err(broken(format!(
                    "<contact> must not set `{set}`: the contact's stiffness comes from the plate calibration, its impedance from physics.contact_solimp"
                )));
            }
        }
        let friction = attr(&mjcf[contact.0..contact.1], "friction")
            .and_then(|f| f.split_whitespace().next().and_then(|x| x.parse::<f64>().ok()))
            .ok_or_else(|| broken("the flexcomp's <contact> needs a friction".into()))?;

        // Compile it alone, with a placeholder elasticity, to read what MuJoCo builds.
        let probe = ProduceItem::with_elasticity(mjcf, 1e5, 0.3, None);
        let m = MjModel::from_xml_string(&probe).map_err(|e| broken(format!("MuJoCo cannot compile it: {e:?}")))?;
        let flex = m
            .name_to_id(_mjtObjBase::mjOBJ_FLEX, FLEX_NAME)
            .ok_or_else(|| broken(format!("no flex named `{FLEX_NAME}` after compiling")))?;
        let nodes = (m.flex_nodeadr()[flex] as usize)..(m.flex_nodeadr()[flex] + m.flex_nodenum()[flex]) as usize;
        let mass_kg: f64 = m.flex_nodebodyid()[nodes].iter().map(|&b| m.body_mass()[b as usize]).sum();
        if !(mass_kg > 0.0 && mass_kg.is_finite()) {
            return Err(broken(format!("the flex has no mass ({mass_kg} kg)")));
        }
        let mut data = MjData::new(&m);
        data.forward();
        let verts = (m.flex_vertadr()[flex] as usize)..(m.flex_vertadr()[flex] + m.flex_vertnum()[flex]) as usize;
        let radius = m.flex_radius()[flex];
        let mut lo = [f64::INFINITY; 3];
        let mut hi = [f64::NEG_INFINITY; 3];
        for p in &data.flexvert_xpos()[verts] {
            for k in 0..3 {
                lo[k] = lo[k].min(p[k]);
                hi[k] = hi[k].max(p[k]);
            }
        }
        let centre: [f64; 3] = std::array::from_fn(|k| (lo[k] + hi[k]) / 2.0);
        if centre.iter().any(|c| c.abs() > 1e-4) {
            return Err(broken(format!("the item's centre must be at the file's origin, it is at {centre:?} m")));
        }
        let radii_m = std::array::from_fn(|k| (hi[k] - lo[k]) / 2.0 + radius);
        let need = |name: &str| {
            numeric(&m, name)
                .ok_or_else(|| broken(format!("no <custom><numeric name=\"{name}\" .../> (see docs/guide/objects.md)")))
        };
        let properties = ProduceProperties {
            modulus_pa: need("produce_modulus_pa")?,
            poisson: need("produce_poisson")?,
            bruise_pa: need("produce_bruise_pa")?,
            detach_n: numeric(&m, "produce_detach_n"),
        };
        let item = ProduceItem {
            source: source.to_string(),
            mjcf: mjcf.to_string(),
            mass_kg,
            radii_m,
            wrap_m: numeric(&m, "produce_wrap_m").unwrap_or(0.0),
            properties,
            dof,
            count,
            friction,
        };
        item.check().map_err(|(name, reason)| broken(format!("{name}: {reason}")))?;
        Ok(item)
    }

    /// The properties' faults, each with the name of the numeric (or key) at fault.
    fn check(&self) -> Result<(), (&'static str, String)> {
        let p = &self.properties;
        if let Some(f) = modulus_fault(p.modulus_pa) {
            return Err(("produce_modulus_pa", f));
        }
        if let Some(f) = poisson_fault(p.poisson) {
            return Err(("produce_poisson", f));
        }
        if !(p.bruise_pa > 0.0 && p.bruise_pa.is_finite()) {
            return Err(("produce_bruise_pa", format!("must be a positive pressure in Pa, got {}", p.bruise_pa)));
        }
        if let Some(d) = p.detach_n.filter(|d| !(*d > 0.0 && d.is_finite())) {
            return Err(("produce_detach_n", format!("must be a positive force in N, got {d}")));
        }
        if self.wrap_m.is_nan() || self.wrap_m.abs() >= self.radii_m[2] {
            return Err((
                "produce_wrap_m",
                format!("must lie within the item's height (±{} m), got {}", self.radii_m[2], self.wrap_m),
            ));
        }
        Ok(())
    }

    /// The item with a scenario's `[produce]` overrides and `[object]`'s mass and friction
    /// applied. The grid and the degrees of freedom change the document; the size stays.
    pub fn configured(
        &self,
        produce: &ProduceConfig,
        mass_kg: Option<f64>,
        friction: Option<f64>,
    ) -> Result<ProduceItem, PhysicsError> {
        let mut item = self.clone();
        let config = |key: &str, reason: String| PhysicsError::Config { key: key.into(), reason };
        let p = &mut item.properties;
        if let Some(e) = produce.modulus_pa {
            p.modulus_pa = e;
        }
        if let Some(nu) = produce.poisson {
            p.poisson = nu;
        }
        if let Some(b) = produce.bruise_pa {
            p.bruise_pa = b;
        }
        if let Some(d) = produce.detach_n {
            p.detach_n = Some(d);
        }
        if produce.harvest && p.detach_n.is_none() {
            return Err(config(
                "produce.harvest",
                format!("{} gives no detachment force (produce_detach_n); set produce.detach_n", self.source),
            ));
        }
        let (open, end) = flexcomp_span(&item.mjcf).expect("read checked the flexcomp");
        let mut tag = item.mjcf[open..end].to_string();
        if let Some(dof) = produce.dof {
            item.dof = dof;
            tag = with_attr(&tag, "dof", dof.name());
        }
        if let Some(n) = produce.count {
            let count = [n; 3];
            if let Some(fault) = grid_fault(count) {
                return Err(config("produce.count", fault));
            }
            // The same size on the new grid: spacing × (count − 1) is each axis's extent.
            let radius: f64 = attr(&tag, "radius").and_then(|r| r.parse().ok()).unwrap_or(0.0);
            let spacing: Vec<String> =
                item.radii_m.iter().map(|r| format!("{:?}", 2.0 * (r - radius) / f64::from(n - 1))).collect();
            tag = with_attr(&tag, "count", &format!("{n} {n} {n}"));
            tag = with_attr(&tag, "spacing", &spacing.join(" "));
            item.count = count;
        }
        if let Some(m) = mass_kg {
            item.mass_kg = m;
            tag = with_attr(&tag, "mass", &format!("{m:?}"));
        }
        item.mjcf = edit_span(&item.mjcf, (open, end), |_| tag);
        if let Some(mu) = friction {
            item.friction = mu;
            let span = child_span(&item.mjcf, "contact").expect("read checked the contact");
            item.mjcf = edit_span(&item.mjcf, span, |t| {
                let rest: Vec<String> = attr(t, "friction")
                    .map_or_else(Vec::new, |f| f.split_whitespace().skip(1).map(String::from).collect());
                with_attr(t, "friction", &std::iter::once(format!("{mu:?}")).chain(rest).collect::<Vec<_>>().join(" "))
            });
        }
        item.check()
            .map_err(|(name, reason)| config(&format!("produce.{}", name.trim_start_matches("produce_")), reason))?;
        Ok(item)
    }

    /// The item's document with its flex's elasticity set (the item's modulus and Poisson's
    /// ratio) and its contact: `contact` is the contact's stiffness and damping in MuJoCo's direct
    /// `solref` format (\[1/s²\], \[1/s\]; the plate calibration's, [`super::plates::calibrate`])
    /// and the impedance `solimp` (the cell's, `physics.contact_solimp`).
    pub fn document(&self, contact: ([f64; 2], [f64; 3])) -> String {
        ProduceItem::with_elasticity(&self.mjcf, self.properties.modulus_pa, self.properties.poisson, Some(contact))
    }

    fn with_elasticity(mjcf: &str, young_pa: f64, poisson: f64, contact: Option<([f64; 2], [f64; 3])>) -> String {
        let mut text = match child_span(mjcf, "elasticity") {
            Some(span) => edit_span(mjcf, span, |t| {
                with_attr(&with_attr(t, "young", &format!("{young_pa:?}")), "poisson", &format!("{poisson:?}"))
            }),
            None => mjcf.to_string(),
        };
        if let (Some(([k, b], imp)), Some(span)) = (contact, child_span(&text, "contact")) {
            text = edit_span(&text, span, |t| {
                let solref = format!("{:?} {:?}", -k, -b);
                let solimp = format!("{:?} {:?} {:?} 0.5 2", imp[0], imp[1], imp[2]);
                with_attr(&with_attr(t, "solref", &solref), "solimp", &solimp)
            });
        }
        text
    }

    /// The item's principal curvatures at the contact point `dir` (a direction from its centre)
    /// \[1/m\], both taken as the square root of the ellipsoid's Gaussian curvature there (the
    /// two principal curvatures' geometric mean, which is what Hertz's effective radius of a
    /// point contact takes).
    pub fn curvatures(&self, dir: [f64; 3]) -> [f64; 2] {
        let [a, b, c] = self.radii_m;
        let n = (dir[0] * dir[0] + dir[1] * dir[1] + dir[2] * dir[2]).sqrt();
        if n.is_nan() || n <= 0.0 {
            return [1.0 / a; 2];
        }
        // The surface point along `dir`, then K = 1 / (a²b²c² (x²/a⁴ + y²/b⁴ + z²/c⁴)²).
        let d = dir.map(|v| v / n);
        let t = 1.0 / ((d[0] / a).powi(2) + (d[1] / b).powi(2) + (d[2] / c).powi(2)).sqrt();
        let [x, y, z] = d.map(|v| v * t);
        let s = x * x / a.powi(4) + y * y / b.powi(4) + z * z / c.powi(4);
        let gauss = 1.0 / (a * a * b * b * c * c * s * s);
        [gauss.sqrt(); 2]
    }

    /// The flex's `<contact>` attribute `name` as the file (and the overrides) give it (`None`
    /// when unset: MuJoCo's default).
    pub fn contact_attr(&self, name: &str) -> Option<String> {
        child_span(&self.mjcf, "contact").and_then(|(a, b)| attr(&self.mjcf[a..b], name))
    }

    /// The radius the finger wraps (the larger horizontal semi-axis) \[m\].
    pub fn grip_radius_m(&self) -> f64 {
        self.radii_m[0].max(self.radii_m[1])
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    const GOOD: &str = r#"<mujoco>
  <custom>
    <numeric name="produce_modulus_pa" data="6e5"/>
    <numeric name="produce_poisson" data="0.45"/>
    <numeric name="produce_bruise_pa" data="1.2e5"/>
    <numeric name="produce_detach_n" data="8"/>
  </custom>
  <worldbody>
    <flexcomp name="produce" type="ellipsoid" count="5 5 5" spacing="0.0074 0.0074 0.0074" dim="3"
              radius="0.0002" mass="0.012" dof="trilinear">
      <elasticity damping="0.001"/>
      <contact selfcollide="none" friction="0.6 0.005 0.0001"/>
    </flexcomp>
  </worldbody>
</mujoco>"#;

    #[test]
    fn reads_mass_size_and_properties_from_the_file() {
        let p = ProduceItem::read("tomato.xml", GOOD).unwrap();
        assert!((p.mass_kg - 0.012).abs() < 1e-12, "{}", p.mass_kg);
        for r in p.radii_m {
            assert!((r - 0.015).abs() < 1e-9, "{r}");
        }
        assert_eq!((p.dof, p.count, p.friction), (Dof::Trilinear, [5; 3], 0.6));
        assert_eq!(
            p.properties,
            ProduceProperties { modulus_pa: 6e5, poisson: 0.45, bruise_pa: 1.2e5, detach_n: Some(8.0) }
        );
        // A sphere's curvature is its radius' inverse in every direction.
        let k = p.curvatures([0.3, -0.2, 0.9]);
        assert!((k[0] - 1.0 / 0.015).abs() < 1e-6 && k[0] == k[1], "{k:?}");
    }

    #[test]
    fn the_elasticity_is_set_once_and_overrides_change_the_document() {
        let p = ProduceItem::read("tomato.xml", GOOD).unwrap();
        let doc = p.document(([1e5, 632.0], [0.95, 0.99, 0.001]));
        assert!(doc.contains(r#"<elasticity damping="0.001" young="600000.0" poisson="0.45"/>"#), "{doc}");
        assert!(doc.contains(r#"solref="-100000.0 -632.0" solimp="0.95 0.99 0.001 0.5 2""#), "{doc}");
        let config = ProduceConfig { count: Some(7), dof: Some(Dof::Quadratic), ..Default::default() };
        let q = p.configured(&config, Some(0.02), Some(0.9)).unwrap();
        assert!(q.mjcf.contains(r#"count="7 7 7""#) && q.mjcf.contains(r#"dof="quadratic""#), "{}", q.mjcf);
        assert!(q.mjcf.contains(r#"mass="0.02""#) && q.mjcf.contains(r#"friction="0.9 0.005 0.0001""#));
        let again = ProduceItem::read("again", &q.mjcf).unwrap();
        for (a, b) in again.radii_m.iter().zip(p.radii_m) {
            assert!((a - b).abs() < 1e-9, "the size stays on a finer grid: {a} against {b}");
        }
        assert_eq!((again.count, again.dof), ([7; 3], Dof::Quadratic));
        // The mass is the nodes' masses summed: the file's to rounding.
        assert!((again.mass_kg - 0.02).abs() < 1e-12, "{}", again.mass_kg);
    }

    #[test]
    fn bad_properties_name_the_numeric_or_the_key() {
        let cases = [
            (GOOD.replace(r#"data="0.45""#, r#"data="0.5""#), "produce_poisson"),
            (GOOD.replace(r#"data="0.45""#, r#"data="-1""#), "produce_poisson"),
            (GOOD.replace(r#"data="6e5""#, r#"data="0""#), "produce_modulus_pa"),
            (GOOD.replace(r#"<elasticity damping"#, r#"<elasticity young="1e5" damping"#), "must not set `young`"),
            (
                GOOD.replace(r#"<contact selfcollide"#, r#"<contact solref="0.01 1" selfcollide"#),
                "must not set `solref`",
            ),
            (GOOD.replace(r#"dof="trilinear""#, r#"dof="full""#), "interpolated"),
            (GOOD.replace(r#"type="ellipsoid""#, r#"type="box""#), "ellipsoid"),
            (GOOD.replace(r#"name="produce_bruise_pa""#, r#"name="bruise""#), "produce_bruise_pa"),
            (GOOD.replace(r#"count="5 5 5""#, r#"count="2 5 5""#), "at least 3"),
        ];
        for (text, what) in cases {
            let e = ProduceItem::read("mine.xml", &text).unwrap_err().to_string();
            assert!(e.contains("mine.xml") && e.contains(what), "{what}: {e}");
        }
        let p = ProduceItem::read("tomato.xml", GOOD).unwrap();
        let bad = |c: ProduceConfig| p.configured(&c, None, None).unwrap_err().to_string();
        assert!(bad(ProduceConfig { poisson: Some(0.5), ..Default::default() }).contains("produce.poisson"));
        assert!(bad(ProduceConfig { modulus_pa: Some(-1.0), ..Default::default() }).contains("produce.modulus_pa"));
        let huge = bad(ProduceConfig { count: Some(100_000), ..Default::default() });
        assert!(huge.contains("produce.count") && huge.contains("GB"), "{huge}");
    }
}
