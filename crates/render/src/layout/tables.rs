//! The scene's one f32 `tables` buffer under construction: the light CDF, the environment map
//! and its CDFs, the Fresnel tables and the tabulated NDFs, each at its offset.

/// f32 words at offsets, and how many words each input (a fit file, the environment map, the
/// scene's lights) put there, for the error when they do not fit.
#[derive(Default)]
pub struct Tables {
    pub words: Vec<f32>,
    sources: Vec<(String, u64)>,
}

impl Tables {
    /// Appends `values` on behalf of `source`; returns their offset in words.
    pub fn push(&mut self, source: &str, values: impl IntoIterator<Item = f32>) -> u32 {
        let at = self.words.len() as u32;
        self.words.extend(values);
        let added = self.words.len() as u64 - u64::from(at);
        match self.sources.iter_mut().find(|(s, _)| s == source) {
            Some((_, n)) => *n += added,
            None => self.sources.push((source.to_owned(), added)),
        }
        at
    }

    /// What filled the tables, largest first: "the environment map sky.exr (12582912 bytes), …".
    pub fn described(&self) -> String {
        let mut by_size = self.sources.clone();
        by_size.sort_by_key(|(_, n)| std::cmp::Reverse(*n));
        let parts: Vec<String> = by_size
            .iter()
            .take(4)
            .map(|(s, n)| format!("{s} ({} bytes)", 4 * n))
            .collect();
        let more = by_size.len().saturating_sub(parts.len());
        if more > 0 {
            format!("{} and {more} more", parts.join(", "))
        } else {
            parts.join(", ")
        }
    }
}
