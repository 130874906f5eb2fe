//! The synthetic photographs the try-on is tested and documented with: the 9AR mannequin made
//! two sizes larger (bust 88 cm), posed, photographed by a known camera, skin-coloured over a
//! plain background ([`super::pose::synthetic_photo`]).

use atelier_body::Part;
use atelier_body::build::Sizes;

use super::camera::Camera;

/// One synthetic photograph: what it shows, and the truth the fit should recover.
#[derive(Clone, Debug)]
pub struct Example {
    /// Short name (`standing`, `arms_raised`, `mid_stride`).
    pub name: &'static str,
    /// The body's sizes.
    pub sizes: Sizes,
    /// Joint angles, degrees, by part index.
    pub angles: [[f64; 3]; 17],
    /// The camera.
    pub camera: Camera,
    /// Width and height, pixels.
    pub size: (usize, usize),
}

fn angles(list: &[(Part, [f64; 3])]) -> [[f64; 3]; 17] {
    let mut a = [[0.0; 3]; 17];
    for &(p, v) in list {
        a[p.index()] = v;
    }
    a
}

/// Standing, arms raised sideways with the elbows bent, and mid-stride; photographed from 20°
/// to the body's right, and 30° to its left (a stride seen exactly from the front would hide
/// which leg is forward).
pub fn examples() -> Vec<Example> {
    use Part::*;
    let g = 88.0 / Sizes::JIS_9AR.bust_cm;
    let sizes = Sizes {
        height_cm: 158.0,
        bust_cm: 88.0,
        waist_cm: Sizes::JIS_9AR.waist_cm * g,
        hip_cm: Sizes::JIS_9AR.hip_cm * g,
    };
    let camera = |yaw_deg: f64| Camera {
        yaw_deg,
        scale: 240.0,
        origin_px: [210.0, 435.0],
    };
    vec![
        Example {
            name: "standing",
            sizes,
            angles: angles(&[
                (UpperArmLeft, [0.0, 0.0, 6.0]),
                (UpperArmRight, [0.0, 0.0, -4.0]),
            ]),
            camera: camera(-20.0),
            size: (420, 460),
        },
        Example {
            name: "arms_raised",
            sizes,
            angles: angles(&[
                (UpperArmLeft, [-10.0, 0.0, 75.0]),
                (UpperArmRight, [-10.0, 0.0, -75.0]),
                (ForearmLeft, [-20.0, 0.0, 0.0]),
                (ForearmRight, [-20.0, 0.0, 0.0]),
            ]),
            camera: camera(30.0),
            size: (420, 460),
        },
        Example {
            name: "mid_stride",
            sizes,
            angles: angles(&[
                (ThighLeft, [-20.0, 0.0, 0.0]),
                (ThighRight, [12.0, 0.0, 0.0]),
                (ShinLeft, [10.0, 0.0, 0.0]),
                (ShinRight, [35.0, 0.0, 0.0]),
                (UpperArmLeft, [15.0, 0.0, 0.0]),
                (UpperArmRight, [-15.0, 0.0, 0.0]),
                (ForearmLeft, [-20.0, 0.0, 0.0]),
                (ForearmRight, [-25.0, 0.0, 0.0]),
            ]),
            camera: camera(30.0),
            size: (420, 460),
        },
    ]
}
