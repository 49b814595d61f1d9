//! Writing the film: the course's 8-bit PNG conversion, linear EXR, unsupported extensions,
//! and atomic replacement (no partial or empty file is ever left behind).

use std::path::Path;

use glint_io::{write_image, ImageWriteError};
use glint_render::{Film, Vec3};

fn film() -> Film {
    Film {
        pixels: vec![
            Vec3::new(0.5, 1.2, -0.1),
            Vec3::new(f32::NAN, 0.999, 1.0 / 255.0),
            Vec3::new(0.0, 0.25, 0.75),
            Vec3::splat(1.0),
            Vec3::splat(0.2),
            Vec3::new(3.5, 0.1, 0.9),
        ],
        ..Film::new(3, 2)
    }
}

fn directory_entries(directory: &Path) -> Vec<String> {
    let mut names: Vec<String> = std::fs::read_dir(directory)
        .unwrap()
        .map(|entry| entry.unwrap().file_name().to_string_lossy().into_owned())
        .collect();
    names.sort();
    names
}

#[test]
fn png_uses_the_course_conversion() {
    let directory = tempfile::tempdir().unwrap();
    let path = directory.path().join("out.png");
    write_image(&path, &film()).unwrap();
    let written = image::open(&path).unwrap();
    assert_eq!(written.color(), image::ColorType::Rgb8);
    let written = written.to_rgb8();
    assert_eq!(written.dimensions(), (3, 2));
    // Row 0 at the top; clamp, then floor(c·255); NaN becomes 0.
    assert_eq!(written.get_pixel(0, 0).0, [127, 255, 0]);
    assert_eq!(written.get_pixel(1, 0).0, [0, 254, 1]);
    assert_eq!(written.get_pixel(2, 0).0, [0, 63, 191]);
    assert_eq!(written.get_pixel(0, 1).0, [255, 255, 255]);
    assert_eq!(written.get_pixel(1, 1).0, [51, 51, 51]);
    assert_eq!(
        written.as_raw().as_slice(),
        film().to_rgb8_course().as_slice()
    );
    assert_eq!(directory_entries(directory.path()), ["out.png"]);
}

#[test]
fn exr_keeps_linear_values() {
    let directory = tempfile::tempdir().unwrap();
    let path = directory.path().join("out.EXR");
    write_image(&path, &film()).unwrap();
    let written = image::open(&path).unwrap().to_rgb32f();
    assert_eq!(written.dimensions(), (3, 2));
    assert_eq!(written.get_pixel(2, 1).0, [3.5, 0.1, 0.9]);
    assert_eq!(written.get_pixel(0, 0).0, [0.5, 1.2, -0.1]);
}

#[test]
fn unsupported_extensions_are_refused_before_anything_is_written() {
    let directory = tempfile::tempdir().unwrap();
    for name in ["out.jpg", "out"] {
        let error = write_image(&directory.path().join(name), &film()).unwrap_err();
        assert!(matches!(
            error,
            ImageWriteError::UnsupportedExtension { .. }
        ));
        let message = error.to_string();
        assert!(message.contains(name), "{message}");
        assert!(message.contains(".png or .exr"), "{message}");
    }
    assert!(directory_entries(directory.path()).is_empty());
}

#[test]
fn a_failed_write_leaves_the_old_file_untouched() {
    let directory = tempfile::tempdir().unwrap();
    let path = directory.path().join("out.png");
    std::fs::write(&path, b"previous image").unwrap();
    let broken = Film {
        pixels: vec![Vec3::ZERO; 3],
        ..Film::new(4, 4)
    };
    let error = write_image(&path, &broken).unwrap_err();
    assert!(
        matches!(error, ImageWriteError::InvalidFilm { .. }),
        "{error}"
    );
    assert_eq!(std::fs::read(&path).unwrap(), b"previous image");
    assert_eq!(directory_entries(directory.path()), ["out.png"]);

    // A directory that does not exist: an I/O error, and no file appears anywhere.
    let missing = directory.path().join("no/such/dir/out.png");
    let error = write_image(&missing, &film()).unwrap_err();
    assert!(matches!(error, ImageWriteError::Io { .. }), "{error}");
    assert_eq!(directory_entries(directory.path()), ["out.png"]);
}

#[test]
fn an_existing_image_is_replaced_whole() {
    let directory = tempfile::tempdir().unwrap();
    let path = directory.path().join("out.png");
    std::fs::write(&path, b"previous image").unwrap();
    write_image(&path, &film()).unwrap();
    assert_eq!(image::open(&path).unwrap().to_rgb8().dimensions(), (3, 2));
    assert_eq!(directory_entries(directory.path()), ["out.png"]);
    #[cfg(unix)]
    {
        use std::os::unix::fs::PermissionsExt;
        let mode = std::fs::metadata(&path).unwrap().permissions().mode();
        assert_ne!(
            mode & 0o044,
            0,
            "the image should be readable by others: {mode:o}"
        );
    }
}

#[test]
fn exr_keeps_windows_sums_and_metadata() {
    let directory = tempfile::tempdir().unwrap();
    let path = directory.path().join("part.exr");
    let mut part = Film {
        origin: (5, 7),
        full_size: (20, 10),
        ..film()
    };
    // Finite: the reader refuses a NaN, which Glint never writes (hostile_images.rs).
    part.pixels[1].x = 0.125;
    part.sums = Some(glint_render::SampleSums {
        radiance: part.pixels.iter().map(|&c| c * 3.0).collect(),
        counts: vec![3, 0, 3, 2, 3, 3],
    });
    let metadata = vec![
        ("glint.seed".to_string(), "7".to_string()),
        ("glint.sample_range".to_string(), "4..7".to_string()),
    ];
    glint_io::write_image_with_metadata(&path, &part, &Default::default(), &metadata).unwrap();
    let read = glint_io::read_exr(&path).unwrap();
    assert_eq!((read.film.origin, read.film.full_size), ((5, 7), (20, 10)));
    assert_eq!((read.film.width, read.film.height), (3, 2));
    let bits = |film: &Film| -> Vec<u32> {
        film.pixels
            .iter()
            .flat_map(|c| c.to_array())
            .map(f32::to_bits)
            .collect()
    };
    assert_eq!(bits(&read.film), bits(&part));
    let (a, b) = (read.film.sums.unwrap(), part.sums.clone().unwrap());
    assert_eq!(a.counts, b.counts);
    assert_eq!(a.radiance[5], b.radiance[5]);
    for entry in &metadata {
        assert!(
            read.metadata.contains(entry),
            "{entry:?} in {:?}",
            read.metadata
        );
    }
    // A tile that does not fit its image is refused.
    let outside = Film {
        origin: (19, 0),
        ..part.clone()
    };
    assert!(glint_io::write_image_with_metadata(
        &path,
        &Film {
            sums: None,
            ..outside
        },
        &Default::default(),
        &[]
    )
    .is_err());
}
