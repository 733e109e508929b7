//! NACA 4-digit airfoil sections (Abbott and von Doenhoff, "Theory of Wing Sections", section 6.4), the ground
//! truth of the simulated propeller's blade sections. Coordinates in millimetres: the leading edge at the origin,
//! the chord along +x (the section's own axes; the propeller places and twists them).

use std::f64::consts::PI;

/// The parts of a section's point at one parameter that do not depend on its thickness, camber or chord: a
/// section that differs only in those places its points from the same stations (a blade whose thickness or camber
/// is off by a scale reuses the stations of its nominal).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct FoilStation {
    /// Chord fraction.
    x: f64,
    /// Half thickness and mean line height and slope per unit thickness and per unit maximum camber.
    half_thickness: f64,
    camber: f64,
    slope: f64,
    /// +1 on the upper surface, -1 on the lower.
    side: f64,
}

/// A NACA 4-digit section "MPTT": maximum camber M% of chord at P tenths of chord, thickness TT% of chord.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Naca4 {
    pub max_camber: f64,
    pub camber_position: f64,
    pub thickness: f64,
    pub chord_mm: f64,
    /// A closed (sharp) trailing edge uses the modified last thickness coefficient -0.1036 instead of -0.1015.
    pub sharp_trailing_edge: bool,
}

impl Naca4 {
    /// Parses the four digits, e.g. "2412".
    pub fn from_digits(digits: &str, chord_mm: f64, sharp_trailing_edge: bool) -> Option<Self> {
        let d: Vec<u32> = digits
            .chars()
            .map(|c| c.to_digit(10))
            .collect::<Option<_>>()?;
        if d.len() != 4 {
            return None;
        }
        Some(Self {
            max_camber: d[0] as f64 / 100.0,
            camber_position: d[1] as f64 / 10.0,
            thickness: (d[2] * 10 + d[3]) as f64 / 100.0,
            chord_mm,
            sharp_trailing_edge,
        })
    }

    /// Half thickness at chord fraction x in [0, 1] (as a fraction of chord).
    #[cfg(test)]
    fn half_thickness(&self, x: f64) -> f64 {
        self.thickness * self.thickness_shape(x)
    }

    /// The half thickness at chord fraction x of a section 1 thick: the thickness scales it.
    fn thickness_shape(&self, x: f64) -> f64 {
        let a4 = if self.sharp_trailing_edge {
            -0.1036
        } else {
            -0.1015
        };
        5.0 * (0.2969 * x.sqrt() - 0.1260 * x - 0.3516 * x * x
            + 0.2843 * x.powi(3)
            + a4 * x.powi(4))
    }

    /// Mean camber line height and slope at chord fraction x.
    #[cfg(test)]
    fn camber(&self, x: f64) -> (f64, f64) {
        let (height, slope) = self.camber_shape(x);
        (self.max_camber * height, self.max_camber * slope)
    }

    /// Mean camber line height and slope at chord fraction x of a section of maximum camber 1: the maximum
    /// camber scales both.
    fn camber_shape(&self, x: f64) -> (f64, f64) {
        let p = self.camber_position;
        if p == 0.0 {
            return (0.0, 0.0);
        }
        if x < p {
            ((2.0 * p * x - x * x) / (p * p), 2.0 * (p - x) / (p * p))
        } else {
            let q = (1.0 - p) * (1.0 - p);
            ((1.0 - 2.0 * p + 2.0 * p * x - x * x) / q, 2.0 * (p - x) / q)
        }
    }

    /// What the point at parameter s is made of, before the thickness, the camber and the chord size it.
    pub fn station(&self, s: f64) -> FoilStation {
        let x = 0.5 * (1.0 + (2.0 * PI * s).cos());
        let (camber, slope) = self.camber_shape(x);
        FoilStation {
            x,
            half_thickness: self.thickness_shape(x),
            camber,
            slope,
            side: if s < 0.5 { 1.0 } else { -1.0 },
        }
    }

    /// The point of this section at `station` (of a section of the same camber position and edge): the half
    /// thickness laid off along the normal of the mean camber line.
    pub fn place(&self, station: &FoilStation) -> [f64; 2] {
        let t = self.thickness * station.half_thickness;
        let (yc, slope) = (
            self.max_camber * station.camber,
            self.max_camber * station.slope,
        );
        // sin and cos of atan(slope).
        let cos = 1.0 / (1.0 + slope * slope).sqrt();
        let sin = slope * cos;
        let px = station.x - station.side * t * sin;
        let py = yc + station.side * t * cos;
        [px * self.chord_mm, py * self.chord_mm]
    }

    /// The point of the section at parameter s in [0, 1): s = 0 is the trailing edge, the upper surface runs to the
    /// leading edge at s = 0.5, the lower surface back to the trailing edge. The chord position follows cosine
    /// spacing (x = (1 + cos 2 pi s) / 2), so that points crowd at both edges, as a scan of a curved edge does.
    pub fn point(&self, s: f64) -> [f64; 2] {
        self.place(&self.station(s))
    }

    /// `count` points evenly spaced in the parameter, in order around the section.
    pub fn points(&self, count: usize) -> Vec<[f64; 2]> {
        (0..count)
            .map(|i| self.point(i as f64 / count as f64))
            .collect()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn naca_2412_has_its_published_thickness_and_camber() {
        let foil = Naca4::from_digits("2412", 100.0, true).unwrap();
        // Maximum thickness of a 12% section is 12 mm on a 100 mm chord, near 30% chord.
        let t = (1..1000)
            .map(|i| 2.0 * foil.half_thickness(i as f64 / 1000.0))
            .fold(0.0, f64::max);
        assert!((t - 0.12).abs() < 2e-4, "max thickness {t}");
        assert!((foil.camber(0.4).0 - 0.02).abs() < 1e-12);
        // A sharp trailing edge closes: both surfaces meet at (100, 0).
        let te = foil.point(0.0);
        assert!(te[0] > 99.99 && te[1].abs() < 1e-3, "trailing edge {te:?}");
        let le = foil.point(0.5);
        assert!(
            le[0].abs() < 1e-9 && le[1].abs() < 1e-9,
            "leading edge {le:?}"
        );
        assert!(Naca4::from_digits("24x2", 1.0, true).is_none());
    }
}
