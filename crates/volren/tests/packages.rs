//! The wire format of paper 03's packages: lossless transfer of the structure, ROI data in
//! the restricted order, byte counts from the serialized buffers, and the bad-input list of
//! check 10 (truncated, corrupted, foreign or inconsistent packages).

use wscg_volren::phantoms::{head, head_tfs};
use wscg_volren::{HybridClient, HybridServer, PiecewiseTransferFunction, Roi, ServerParams};

fn server() -> HybridServer {
    let v = head([96, 96, 48], 3).unwrap();
    HybridServer::new(&v, head_tfs(), 0, ServerParams::default()).unwrap()
}

/// Re-frames a payload with a valid header (to test the checks behind the CRC).
fn reframe(pkg: &[u8], edit: impl FnOnce(&mut Vec<u8>)) -> Vec<u8> {
    let mut payload = pkg[20..].to_vec();
    edit(&mut payload);
    let mut out = pkg[..8].to_vec();
    out.extend_from_slice(&(payload.len() as u64).to_le_bytes());
    out.extend_from_slice(&crc32fast::hash(&payload).to_le_bytes());
    out.extend_from_slice(&payload);
    out
}

#[test]
fn client_rebuilds_the_structure_and_receives_roi_leaves() {
    let s = server();
    let stat = s.static_package();
    let mut c = HybridClient::from_static(&stat).unwrap();
    assert_eq!(c.structure, s.octree().structure);
    assert_eq!(c.lowres.dims(), [24, 24, 12]);
    let pkg = s.roi_package([20, 30, 5], [50, 60, 30]).unwrap();
    c.set_roi(&pkg).unwrap();
    let (roi, _, leaves) = c.roi.as_ref().unwrap();
    assert_eq!(
        *roi,
        Roi {
            min: [16, 16, 0],
            max: [64, 64, 32]
        }
    );
    assert_eq!(&leaves[1..], s.octree().roi_leaves(roi).as_slice());
    // Dynamic package = header (20) + id, box and count (8 + 24 + 8) + 3 bytes a leaf.
    assert_eq!(pkg.len(), 20 + 40 + 3 * (leaves.len() - 1));
    assert!(leaves.len() > 100);
}

#[test]
fn bad_packages_are_rejected() {
    let s = server();
    let stat = s.static_package();
    let roi = s.roi_package([0, 0, 0], [32, 32, 32]).unwrap();
    // Truncated, padded, corrupted, wrong magic, version or kind.
    for bad in [
        stat[..stat.len() - 1].to_vec(),
        [stat.as_slice(), &[0]].concat(),
        {
            let mut b = stat.clone();
            let k = b.len() / 2;
            b[k] ^= 0x40;
            b
        },
        {
            let mut b = stat.clone();
            b[0] = b'X';
            b
        },
        {
            let mut b = stat.clone();
            b[6] = 9;
            b
        },
        roi.clone(),
        stat[..10].to_vec(),
        Vec::new(),
    ] {
        assert!(HybridClient::from_static(&bad).is_err());
    }
    // A payload that passes the CRC but is cut short inside.
    let cut = reframe(&stat, |p| p.truncate(p.len() - 5));
    let err = HybridClient::from_static(&cut).unwrap_err().to_string();
    assert!(
        err.contains("truncated") || err.contains("left over"),
        "{err}"
    );
    let mut c = HybridClient::from_static(&stat).unwrap();
    assert!(
        c.set_roi(&stat).is_err(),
        "a static package is not a ROI package"
    );
    // Another volume's ROI package.
    let other = HybridServer::new(
        &head([96, 96, 48], 4).unwrap(),
        head_tfs(),
        0,
        ServerParams::default(),
    )
    .unwrap();
    let err = c.set_roi(&other.roi_package([0, 0, 0], [32, 32, 32]).unwrap());
    assert!(err.unwrap_err().to_string().contains("another volume"));
    // A leaf count that differs from the one the structure implies.
    let wrong = reframe(&roi, |p| {
        let n = u64::from_le_bytes(p[32..40].try_into().unwrap()) + 1;
        p[32..40].copy_from_slice(&n.to_le_bytes());
        p.extend_from_slice(&[0, 0, 0]);
    });
    assert!(c
        .set_roi(&wrong)
        .unwrap_err()
        .to_string()
        .contains("leaves"));
    // A ROI outside the volume, inverted, or not snapped.
    let outside = reframe(&roi, |p| p[8..12].copy_from_slice(&200u32.to_le_bytes()));
    assert!(c.set_roi(&outside).is_err());
    let unsnapped = reframe(&roi, |p| p[8..12].copy_from_slice(&3u32.to_le_bytes()));
    assert!(c.set_roi(&unsnapped).is_err());
    c.set_roi(&roi).unwrap();
    // Server-side bad input.
    assert!(s.roi_package([50, 0, 0], [40, 10, 10]).is_err());
    assert!(s.roi_package([500, 0, 0], [510, 10, 10]).is_err());
    let v = head([32, 32, 32], 1).unwrap();
    assert!(HybridServer::new(&v, head_tfs(), 2, ServerParams::default()).is_err());
    assert!(HybridServer::new(
        &v,
        Vec::<PiecewiseTransferFunction>::new(),
        0,
        ServerParams::default()
    )
    .is_err());
    let opts = ServerParams::default().steps_sent(5);
    assert!(HybridServer::new(&v, head_tfs(), 0, opts).is_err());
}

#[test]
fn packages_travel_over_a_loopback_socket() {
    use std::sync::Arc;
    use wscg_volren::net::{serve, RemoteServer};
    let s = Arc::new(server());
    let listener = std::net::TcpListener::bind("127.0.0.1:0").unwrap();
    let addr = listener.local_addr().unwrap();
    let srv = Arc::clone(&s);
    let handle = std::thread::spawn(move || serve(srv, listener, Some(1)));
    let mut remote = RemoteServer::connect(addr).unwrap();
    let stat = remote.static_package().unwrap();
    assert_eq!(
        stat,
        s.static_package(),
        "static package changed in transit"
    );
    let mut client = HybridClient::from_static(&stat).unwrap();
    let roi = remote.roi_package([20, 30, 5], [50, 60, 30]).unwrap();
    assert_eq!(roi, s.roi_package([20, 30, 5], [50, 60, 30]).unwrap());
    client.set_roi(&roi).unwrap();
    // A bad ROI is answered with the server's error, and the connection stays usable.
    let err = remote.roi_package([90, 0, 0], [10, 10, 10]).unwrap_err();
    assert!(err.to_string().contains("roi"), "{err}");
    assert_eq!(remote.static_package().unwrap(), stat);
    remote.close().unwrap();
    handle.join().unwrap().unwrap();
}

/// Found by fuzzing (FUZZING.md): a ROI package whose box ends near `u32::MAX` overflowed
/// the snapping to the 16-voxel grid (a panic in debug builds).
#[test]
fn roi_boxes_ending_near_u32_max_are_errors() {
    let s = server();
    let mut c = HybridClient::from_static(&s.static_package()).unwrap();
    let roi = s.roi_package([0, 0, 0], [32, 32, 32]).unwrap();
    for max in [u32::MAX, u32::MAX - 8, u32::MAX - 15] {
        // Payload: volume id (8 bytes), min (3 x 4), max (3 x 4), leaf count, leaves.
        let bad = reframe(&roi, |p| p[20..24].copy_from_slice(&max.to_le_bytes()));
        assert!(c.set_roi(&bad).is_err());
        assert!(s.roi_package([0, 0, 0], [max, 32, 32]).is_ok());
        assert_eq!(
            Roi::snapped([0, 0, 0], [max, 16, 16], [96, 96, 48]).unwrap(),
            Roi {
                min: [0, 0, 0],
                max: [96, 16, 16]
            }
        );
    }
}
