//! Universal Transverse Mercator on the WGS 84 ellipsoid, both ways: Krüger's series to 6th order
//! in the third flattening n (Karney 2011, "Transverse Mercator with an accuracy of a few
//! nanometers", J. Geod. 85:475, eqs. 7–11, 35–36): a few nanometres within 3900 km of the
//! central meridian. Zones 1–60 (central meridian 6·zone − 183°), scale 0.9996, false easting
//! 500 km, false northing 10,000 km in the south.

/// WGS 84 semi-major axis (m).
pub const WGS84_A: f64 = 6378137.0;
/// WGS 84 flattening.
pub const WGS84_F: f64 = 1.0 / 298.257223563;
/// WGS 84 first eccentricity squared.
pub const WGS84_E2: f64 = WGS84_F * (2.0 - WGS84_F);

const K0: f64 = 0.9996;

/// The third flattening n and the rectifying radius A (Karney eq. 14, to n⁶).
fn n_and_a() -> (f64, f64) {
    let n = WGS84_F / (2.0 - WGS84_F);
    let (n2, n4, n6) = (n * n, n.powi(4), n.powi(6));
    (
        n,
        WGS84_A / (1.0 + n) * (1.0 + n2 / 4.0 + n4 / 64.0 + n6 / 256.0),
    )
}

/// The zone's central meridian in degrees.
fn central_meridian(zone: u8) -> f64 {
    f64::from(zone) * 6.0 - 183.0
}

/// Forward UTM: [latitude, longitude] in degrees to [easting, northing] in metres, in `zone`
/// (whatever zone the point itself falls in) and hemisphere `north` (the false northing). The
/// longitude is taken relative to the central meridian modulo 360°.
pub fn forward(zone: u8, north: bool, lat: f64, lon: f64) -> [f64; 2] {
    let (n, a) = n_and_a();
    let [n2, n3, n4, n5, n6] = [2, 3, 4, 5, 6].map(|k| n.powi(k));
    // Karney eq. 35 (GeographicLib's alpcoeff, order 6).
    let alpha = [
        n / 2.0 - 2.0 * n2 / 3.0 + 5.0 * n3 / 16.0 + 41.0 * n4 / 180.0 - 127.0 * n5 / 288.0
            + 7891.0 * n6 / 37800.0,
        13.0 * n2 / 48.0 - 3.0 * n3 / 5.0 + 557.0 * n4 / 1440.0 + 281.0 * n5 / 630.0
            - 1983433.0 * n6 / 1935360.0,
        61.0 * n3 / 240.0 - 103.0 * n4 / 140.0 + 15061.0 * n5 / 26880.0 + 167603.0 * n6 / 181440.0,
        49561.0 * n4 / 161280.0 - 179.0 * n5 / 168.0 + 6601661.0 * n6 / 7257600.0,
        34729.0 * n5 / 80640.0 - 3418889.0 * n6 / 1995840.0,
        212378941.0 * n6 / 319334400.0,
    ];
    let dlon = (lon - central_meridian(zone) + 180.0).rem_euclid(360.0) - 180.0;
    let lam = dlon.to_radians();
    let phi = lat.to_radians();
    // The conformal latitude's tangent τ′ from τ = tan φ (Karney eqs. 7–9).
    let e = WGS84_E2.sqrt();
    let tau = phi.tan();
    let sig = (e * (e * tau / tau.hypot(1.0)).atanh()).sinh();
    let taup = tau * sig.hypot(1.0) - sig * tau.hypot(1.0);
    // Gauss–Schreiber coordinates (eq. 10), ξ′ = π/2 at the poles.
    let (xip, etap) = if phi.abs() >= std::f64::consts::FRAC_PI_2 {
        (std::f64::consts::FRAC_PI_2.copysign(phi), 0.0)
    } else {
        (
            taup.atan2(lam.cos()),
            (lam.sin() / taup.hypot(lam.cos())).asinh(),
        )
    };
    let (mut xi, mut eta) = (xip, etap);
    for (j, al) in alpha.iter().enumerate() {
        let k = 2.0 * (j + 1) as f64;
        xi += al * (k * xip).sin() * (k * etap).cosh();
        eta += al * (k * xip).cos() * (k * etap).sinh();
    }
    let false_northing = if north { 0.0 } else { 10_000_000.0 };
    [500_000.0 + K0 * a * eta, false_northing + K0 * a * xi]
}

/// Inverse UTM: (easting, northing) in metres to [latitude, longitude] in degrees (longitude
/// in (−180, 180]): the series, then the geodetic latitude from the conformal one by Newton's
/// method (Karney eqs. 11, 19–21, 36).
pub fn inverse(zone: u8, north: bool, easting: f64, northing: f64) -> [f64; 2] {
    let (n, a) = n_and_a();
    let [n2, n3, n4, n5, n6] = [2, 3, 4, 5, 6].map(|k| n.powi(k));
    let beta = [
        n / 2.0 - 2.0 * n2 / 3.0 + 37.0 * n3 / 96.0 - n4 / 360.0 - 81.0 * n5 / 512.0
            + 96199.0 * n6 / 604800.0,
        n2 / 48.0 + n3 / 15.0 - 437.0 * n4 / 1440.0 + 46.0 * n5 / 105.0
            - 1118711.0 * n6 / 3870720.0,
        17.0 * n3 / 480.0 - 37.0 * n4 / 840.0 - 209.0 * n5 / 4480.0 + 5569.0 * n6 / 90720.0,
        4397.0 * n4 / 161280.0 - 11.0 * n5 / 504.0 - 830251.0 * n6 / 7257600.0,
        4583.0 * n5 / 161280.0 - 108847.0 * n6 / 3991680.0,
        20648693.0 * n6 / 638668800.0,
    ];
    let xi = (northing - if north { 0.0 } else { 10_000_000.0 }) / (K0 * a);
    let eta = (easting - 500_000.0) / (K0 * a);
    let (mut xp, mut ep) = (xi, eta);
    for (j, b) in beta.iter().enumerate() {
        let k = 2.0 * (j + 1) as f64;
        xp -= b * (k * xi).sin() * (k * eta).cosh();
        ep -= b * (k * xi).cos() * (k * eta).sinh();
    }
    // Tangent of the conformal latitude, then of the geodetic latitude by Newton's method.
    let taup = xp.sin() / ep.sinh().hypot(xp.cos());
    let (e2, e) = (WGS84_E2, WGS84_E2.sqrt());
    let lat = if taup.is_finite() {
        let mut tau = taup / (1.0 - e2);
        for _ in 0..5 {
            // quadratic convergence from τ'/(1 − e²): two steps reach double precision
            let tau1 = tau.hypot(1.0);
            let sig = (e * (e * tau / tau1).atanh()).sinh();
            let taupa = tau * sig.hypot(1.0) - sig * tau1;
            let dtau = (taup - taupa) * (1.0 + (1.0 - e2) * tau * tau)
                / ((1.0 - e2) * tau1 * taupa.hypot(1.0));
            tau += dtau;
        }
        tau.atan().to_degrees()
    } else {
        90f64.copysign(taup)
    };
    let lon = central_meridian(zone) + ep.sinh().atan2(xp.cos()).to_degrees();
    [lat, 180.0 - (180.0 - lon).rem_euclid(360.0)] // in (-180, 180]
}
