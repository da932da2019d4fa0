//! A figure's contour for adaptive maps: which side of a threshold a run's summary field is on.

use tendril_run::summary::{RunSummary, flatten_summary};

/// A summary field (as in `summary.json`, dotted when nested; e.g. `max_fluctuation_pct`) and a
/// threshold in its unit: a point's class says whether the field is at least the threshold.
#[derive(Debug, Clone, PartialEq)]
pub struct Contour {
    /// The summary field.
    pub field: String,
    /// The threshold.
    pub at: f64,
}

impl std::str::FromStr for Contour {
    type Err = String;

    fn from_str(s: &str) -> Result<Self, Self::Err> {
        let (field, at) = s.split_once('=').ok_or_else(|| format!("--contour {s}: expected FIELD=VALUE"))?;
        let at: f64 = at.trim().parse().map_err(|_| format!("--contour {s}: {at} is not a number"))?;
        if !at.is_finite() {
            return Err(format!("--contour {s}: the threshold must be finite"));
        }
        Ok(Contour { field: field.trim().to_string(), at })
    }
}

impl Contour {
    /// Whether the summary's field is at least the threshold (a run with no value there, an
    /// error's, is below: its outcome says why); an error naming the field, and the numeric fields
    /// there are, when the summary has no such number.
    pub fn beyond(&self, summary: &RunSummary) -> anyhow::Result<bool> {
        let fields = flatten_summary(summary);
        match fields.iter().find(|(name, _)| *name == self.field) {
            Some((_, v)) if v.is_empty() => Ok(false),
            Some((_, v)) => match v.parse::<f64>() {
                Ok(v) => Ok(v >= self.at),
                Err(_) => {
                    anyhow::bail!("--contour {}: the summary's {} is {v:?}, not a number", self.field, self.field)
                }
            },
            None => {
                let numeric: Vec<&str> =
                    fields.iter().filter(|(_, v)| v.parse::<f64>().is_ok()).map(|(n, _)| n.as_str()).collect();
                anyhow::bail!("--contour {}: no such summary field; numeric fields: {}", self.field, numeric.join(", "))
            }
        }
    }
}

/// A point's class in an adaptive map: the outcome, whether the force oscillated, and the side of
/// the contour when there is one.
pub type Class = (String, bool, Option<bool>);

/// The class of a run's summary.
pub fn class_of(summary: &RunSummary, contour: Option<&Contour>) -> anyhow::Result<Class> {
    let beyond = contour.map(|c| c.beyond(summary)).transpose()?;
    Ok((summary.outcome.clone(), summary.metrics.oscillating, beyond))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn contours_parse_and_refuse() {
        assert_eq!("max_fluctuation_pct=10".parse(), Ok(Contour { field: "max_fluctuation_pct".into(), at: 10.0 }));
        assert!("max_fluctuation_pct".parse::<Contour>().unwrap_err().contains("FIELD=VALUE"));
        assert!("x=big".parse::<Contour>().unwrap_err().contains("not a number"));
        assert!("x=inf".parse::<Contour>().unwrap_err().contains("finite"));
    }

    #[test]
    fn an_unknown_field_lists_the_numeric_ones() {
        let summary = RunSummary::failed_to_start("crimper", "no".into());
        let err = Contour { field: "nope".into(), at: 1.0 }.beyond(&summary).unwrap_err().to_string();
        assert!(err.contains("no such summary field") && err.contains("sim_time_s"), "{err}");
    }
}
