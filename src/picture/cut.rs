//! `--cut`: half-spaces in which walls are cut away, so that the particles inside a machine show.
//!
//! Syntax: an axis, `<` or `>`, and a coordinate in metres, e.g. `y<0` (cut away the walls on
//! the viewer's side of a front or iso view) or `x>0.1`. Wall polygons are clipped exactly at
//! the plane; bodies are kept, or with `--cut-bodies` removed whole when their centre lies in the
//! half-space (a section through a bed).

use std::str::FromStr;

use glam::DVec3;

/// The half-space `axis > value` (or `< value`) whose walls are removed.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Cut {
    axis: usize,
    greater: bool,
    value: f64,
}

impl FromStr for Cut {
    type Err = String;

    fn from_str(text: &str) -> Result<Self, String> {
        let bad = || {
            format!(
                "cannot read cut '{text}': write an axis, < or > and a coordinate in metres, \
                 e.g. y<0 or x>0.1"
            )
        };
        let text_trimmed: String = text.chars().filter(|c| !c.is_whitespace()).collect();
        let (axis, rest) = text_trimmed.split_at_checked(1).ok_or_else(bad)?;
        let axis = match axis {
            "x" | "X" => 0,
            "y" | "Y" => 1,
            "z" | "Z" => 2,
            _ => return Err(bad()),
        };
        let (greater, value) = if let Some(v) = rest.strip_prefix('>') {
            (true, v)
        } else if let Some(v) = rest.strip_prefix('<') {
            (false, v)
        } else {
            return Err(bad());
        };
        let value: f64 = value.parse().map_err(|_| bad())?;
        if !value.is_finite() {
            return Err(bad());
        }
        Ok(Self {
            axis,
            greater,
            value,
        })
    }
}

impl Cut {
    /// Positive in the half-space that is cut away.
    fn signed(&self, p: DVec3) -> f64 {
        let d = p[self.axis] - self.value;
        if self.greater {
            d
        } else {
            -d
        }
    }

    /// Whether `p` lies in the half-space that is cut away.
    pub fn removes(&self, p: DVec3) -> bool {
        self.signed(p) > 0.0
    }

    /// The part of the convex polygon `corners` that is kept: empty when all of it is cut away.
    pub fn clip(&self, corners: &[DVec3]) -> Vec<DVec3> {
        clip_polygon(corners, |p| self.signed(p))
    }
}

/// The part of the convex polygon `corners` where `signed` is not positive (Sutherland &
/// Hodgman 1974, one plane; `signed` must be affine): empty when nothing is left.
pub fn clip_polygon(corners: &[DVec3], signed: impl Fn(DVec3) -> f64) -> Vec<DVec3> {
    let mut kept = Vec::with_capacity(corners.len() + 1);
    for (k, &p) in corners.iter().enumerate() {
        let q = corners[(k + 1) % corners.len()];
        let (sp, sq) = (signed(p), signed(q));
        if sp <= 0.0 {
            kept.push(p);
        }
        if (sp <= 0.0) != (sq <= 0.0) {
            let t = sp / (sp - sq);
            kept.push(p + t * (q - p));
        }
    }
    if kept.len() < 3 {
        kept.clear();
    }
    kept
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn cuts_parse_and_bad_ones_explain_the_syntax() {
        let c: Cut = "x>0.1".parse().unwrap();
        assert_eq!((c.axis, c.greater, c.value), (0, true, 0.1));
        let c: Cut = " y < -2e-3".parse().unwrap();
        assert_eq!((c.axis, c.greater, c.value), (1, false, -2e-3));
        for bad in ["", "w>1", "x=1", "x>", "x>abc", "x>inf"] {
            let err = bad.parse::<Cut>().unwrap_err();
            assert!(err.contains("e.g. y<0"), "{bad}: {err}");
        }
    }

    #[test]
    fn a_square_is_clipped_at_the_plane() {
        let square = [
            DVec3::new(0.0, 0.0, 0.0),
            DVec3::new(1.0, 0.0, 0.0),
            DVec3::new(1.0, 1.0, 0.0),
            DVec3::new(0.0, 1.0, 0.0),
        ];
        let cut: Cut = "x>0.25".parse().unwrap();
        let kept = cut.clip(&square);
        assert_eq!(kept.len(), 4);
        assert!(kept.iter().all(|p| p.x <= 0.25));
        assert!(kept.iter().any(|p| p.x == 0.25));
        assert!("x<2".parse::<Cut>().unwrap().clip(&square).is_empty());
        assert_eq!("x>2".parse::<Cut>().unwrap().clip(&square), square);
        assert!(cut.removes(DVec3::X) && !cut.removes(DVec3::ZERO));
    }
}
