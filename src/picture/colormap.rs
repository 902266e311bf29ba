//! The colour scale: Turbo (Mikhailov 2019, Google AI blog), an improved rainbow, here by its
//! published degree-5 polynomial fit. A rainbow is what DEM users read at a glance (it is also
//! what LIGGGHTS' and ParaView's users are used to); Turbo keeps its order without jet's bands.
//! Its darkest ends are left out (0.1–0.95 of the map), because shading darkens the colour again
//! and a near-black sphere shows no shape.

/// A linear RGB colour, each channel in [0, 1].
pub type Rgb = [f32; 3];

/// The colour for `t` in [0, 1] (clamped): blue at 0, green-yellow in the middle, red at 1.
pub fn turbo(t: f64) -> Rgb {
    let t = 0.1 + 0.85 * t.clamp(0.0, 1.0);
    let poly = |c: [f64; 6]| {
        let v = c[0] + t * (c[1] + t * (c[2] + t * (c[3] + t * (c[4] + t * c[5]))));
        v.clamp(0.0, 1.0) as f32
    };
    [
        poly([
            0.135_721_38,
            4.615_392_6,
            -42.660_322_58,
            132.131_082_34,
            -152.942_393_96,
            59.286_379_43,
        ]),
        poly([
            0.091_402_61,
            2.194_188_39,
            4.842_966_58,
            -14.185_033_33,
            4.277_298_57,
            2.829_566_04,
        ]),
        poly([
            0.106_673_3,
            12.641_946_08,
            -60.582_048_36,
            110.362_767_71,
            -89.903_109_12,
            27.348_249_73,
        ]),
    ]
}

/// Ten distinct colours for categories (matplotlib's tab10), by number: category `k` keeps its
/// colour in every frame whatever other categories there are.
pub fn category(k: usize) -> Rgb {
    const TAB10: [[u8; 3]; 10] = [
        [31, 119, 180],
        [255, 127, 14],
        [44, 160, 44],
        [214, 39, 40],
        [148, 103, 189],
        [140, 86, 75],
        [227, 119, 194],
        [127, 127, 127],
        [188, 189, 34],
        [23, 190, 207],
    ];
    TAB10[k % TAB10.len()].map(|c| f32::from(c) / 255.0)
}

/// Where `value` lies in `[low, high]`, as a fraction; the middle for an empty range, so a
/// field with one value shows in one colour rather than failing.
pub fn fraction(value: f64, low: f64, high: f64) -> f64 {
    if high > low {
        ((value - low) / (high - low)).clamp(0.0, 1.0)
    } else {
        0.5
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn low_is_blue_middle_green_high_red() {
        let [r, g, b] = turbo(0.0);
        assert!(b > 0.7 && r < 0.4 && g < 0.5, "{r} {g} {b}");
        let [r, g, b] = turbo(0.5);
        assert!(g > 0.8 && g > b, "{r} {g} {b}");
        let [r, g, b] = turbo(1.0);
        assert!(r > 0.6 && b < 0.2 && g < 0.4, "{r} {g} {b}");
        assert_eq!(turbo(-3.0), turbo(0.0));
        assert_eq!(turbo(7.0), turbo(1.0));
    }

    #[test]
    fn fraction_of_an_empty_range_is_the_middle() {
        assert_eq!(fraction(2.0, 1.0, 3.0), 0.5);
        assert_eq!(fraction(5.0, 1.0, 3.0), 1.0);
        assert_eq!(fraction(5.0, 5.0, 5.0), 0.5);
    }
}
