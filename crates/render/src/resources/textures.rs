//! The scene's textures in one u32 buffer: a header (offset, width, height, srgb) per texture,
//! then every texture's RGBA8 texels.

use crate::scene::Texture;

pub fn texture_words(textures: &[Texture]) -> Vec<u32> {
    let mut words: Vec<u32> = vec![0; 4 * textures.len()];
    for (i, tex) in textures.iter().enumerate() {
        let off = words.len() as u32;
        words[4 * i..4 * i + 4].copy_from_slice(&[off, tex.width, tex.height, tex.srgb as u32]);
        words.extend(tex.texels.iter().map(|c| u32::from_le_bytes(*c)));
    }
    if words.is_empty() {
        // A binding cannot be empty.
        words.push(0);
    }
    words
}
