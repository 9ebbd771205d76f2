//! A walk over the data elements of a DICOM file before dicom-rs parses it, refusing a value
//! longer than the bytes that follow it and sequences nested too deeply.
//!
//! The parser of dicom-rs 0.10 reserves and zero-fills each value at its declared length
//! before reading it, so a 1 KB file declaring a 4 GB value costs 4 GB of memory (and can
//! abort the process), and it builds nested sequences recursively. The walk follows the
//! encoding rules of DICOM PS3.5 (sections 7.1 to 7.5: explicit and implicit VR elements,
//! defined and undefined lengths, items and delimitation items; section A.4: encapsulated
//! pixel data, whose items are fragments) as the parser reads them: the file meta group in
//! explicit VR little endian, then the data set in the transfer syntax the meta group names
//! (implicit VR little endian, explicit VR big endian, deflated explicit VR little endian,
//! inflated here up to the memory limit; explicit VR little endian otherwise). A truncated
//! element ends the walk: the parser reports it.

use std::io::Read;

use dicom_core::dictionary::{DataDictionary, DataDictionaryEntry};
use dicom_core::{Tag, VR};
use dicom_dictionary_std::StandardDataDictionary;

/// Sequences and items nested deeper than this are refused (real files nest a few levels).
pub(super) const MAX_DEPTH: usize = 64;

const IMPLICIT_VR_LE: &str = "1.2.840.10008.1.2";
const EXPLICIT_VR_BE: &str = "1.2.840.10008.1.2.2";
const DEFLATED_EXPLICIT_VR_LE: &str = "1.2.840.10008.1.2.1.99";

const ITEM: Tag = Tag(0xFFFE, 0xE000);
const ITEM_END: Tag = Tag(0xFFFE, 0xE00D);
const SEQUENCE_END: Tag = Tag(0xFFFE, 0xE0DD);
const PIXEL_DATA: Tag = Tag(0x7FE0, 0x0010);
const UNDEFINED: u32 = u32::MAX;

#[derive(Clone, Copy, PartialEq)]
enum Syntax {
    ExplicitLe,
    ExplicitBe,
    ImplicitLe,
}

/// What the walk is inside of.
#[derive(Clone, Copy, PartialEq)]
enum Container {
    /// A sequence (its items hold data sets).
    Sequence,
    /// Encapsulated pixel data (its items are fragments).
    Fragments,
    /// An item of a sequence.
    Item,
}

/// Checks the value lengths of the file `after_preamble` (the bytes after `DICM`); the
/// reason of a refusal names the element and its offset in the file.
pub(super) fn check(after_preamble: &[u8]) -> std::result::Result<(), String> {
    // The file meta group, in explicit VR little endian, as dicom-rs 0.10 reads it
    // (`FileMetaTable::read_from`): the group length (0002,0000) first, then whole elements,
    // of any group, until their headers and values add up to that length. A file whose
    // mutated tags leave group 0002 early is read on by the parser, so the walk must be too.
    let mut meta = Walker::new(after_preamble, Syntax::ExplicitLe, 132);
    let mut syntax_uid = String::new();
    let group_length = match meta.header()? {
        Some(h) if h.tag == Tag(0x0002, 0x0000) && h.len == 4 => {
            let Some(value) = meta.bytes::<4>(meta.pos) else {
                return Ok(());
            };
            meta.pos += 4;
            u32::from_le_bytes(value)
        }
        // The parser refuses the file.
        _ => return Ok(()),
    };
    let start = meta.pos;
    while ((meta.pos - start) as u64) < u64::from(group_length) {
        let Some(h) = meta.header()? else {
            return Ok(());
        };
        if h.len == UNDEFINED {
            return Ok(());
        }
        // Meta values are read whole, whatever their VR.
        meta.check_fits(&h)?;
        let end = (meta.pos + h.len as usize).min(meta.data.len());
        let value = &meta.data[meta.pos..end];
        meta.pos = end;
        if h.tag == Tag(0x0002, 0x0010) {
            syntax_uid = String::from_utf8_lossy(value)
                .trim_end_matches(['\0', ' '])
                .to_string();
        }
    }
    let (rest, offset) = (&after_preamble[meta.pos..], 132 + meta.pos);
    match syntax_uid.as_str() {
        IMPLICIT_VR_LE => Walker::new(rest, Syntax::ImplicitLe, offset).data_set(),
        EXPLICIT_VR_BE => Walker::new(rest, Syntax::ExplicitBe, offset).data_set(),
        DEFLATED_EXPLICIT_VR_LE => {
            // What inflates before an error or the memory limit; the parser fails there too.
            let limit = crate::memory_limit::limit();
            let mut inflated = Vec::new();
            let read = flate2::read::DeflateDecoder::new(rest)
                .take(limit.saturating_add(1))
                .read_to_end(&mut inflated);
            if read.is_ok() && inflated.len() as u64 > limit {
                return Err(format!(
                    "the deflated data set inflates to more than the memory limit of {limit} \
                     bytes"
                ));
            }
            // Offsets in the inflated data set.
            Walker::new(&inflated, Syntax::ExplicitLe, 0).data_set()
        }
        _ => Walker::new(rest, Syntax::ExplicitLe, offset).data_set(),
    }
}

/// A data element header.
struct Header {
    tag: Tag,
    vr: VR,
    len: u32,
    /// Offset of the header in the file, for messages.
    at: usize,
}

struct Walker<'a> {
    data: &'a [u8],
    pos: usize,
    syntax: Syntax,
    /// Offset of `data[0]` in the file.
    offset: usize,
}

impl<'a> Walker<'a> {
    fn new(data: &'a [u8], syntax: Syntax, offset: usize) -> Self {
        Walker {
            data,
            pos: 0,
            syntax,
            offset,
        }
    }

    fn bytes<const N: usize>(&self, at: usize) -> Option<[u8; N]> {
        self.data.get(at..at.checked_add(N)?)?.try_into().ok()
    }

    fn u16_at(&self, at: usize) -> Option<u16> {
        let b = self.bytes::<2>(at)?;
        Some(match self.syntax {
            Syntax::ExplicitBe => u16::from_be_bytes(b),
            _ => u16::from_le_bytes(b),
        })
    }

    fn u32_at(&self, at: usize) -> Option<u32> {
        let b = self.bytes::<4>(at)?;
        Some(match self.syntax {
            Syntax::ExplicitBe => u32::from_be_bytes(b),
            _ => u32::from_le_bytes(b),
        })
    }

    /// The next element header (`None` at the end or in a truncated header).
    fn header(&mut self) -> std::result::Result<Option<Header>, String> {
        let at = self.pos;
        let (Some(group), Some(element)) = (self.u16_at(at), self.u16_at(at + 2)) else {
            return Ok(None);
        };
        let tag = Tag(group, element);
        // Items and delimitation items: tag and 4-byte length, no VR (PS3.5 section 7.5).
        let (vr, len, size) = if group == 0xFFFE {
            match self.u32_at(at + 4) {
                Some(len) => (VR::UN, len, 8),
                None => return Ok(None),
            }
        } else if self.syntax == Syntax::ImplicitLe {
            let vr = if tag == PIXEL_DATA || (group >> 8 == 0x60 && element == 0x3000) {
                VR::OW
            } else {
                StandardDataDictionary
                    .by_tag(tag)
                    .map(|e| e.vr().relaxed())
                    .unwrap_or(VR::UN)
            };
            match self.u32_at(at + 4) {
                Some(len) => (vr, len, 8),
                None => return Ok(None),
            }
        } else {
            let Some(code) = self.bytes::<2>(at + 4) else {
                return Ok(None);
            };
            let vr = VR::from_binary(code).unwrap_or(VR::UN);
            // The VRs with a 2-byte length (PS3.5 table 7.1-2); every other has 2 reserved
            // bytes and a 4-byte length, as the parser reads unknown VRs.
            use VR::*;
            let short = matches!(
                vr,
                AE | AS
                    | AT
                    | CS
                    | DA
                    | DS
                    | DT
                    | FL
                    | FD
                    | IS
                    | LO
                    | LT
                    | PN
                    | SH
                    | SL
                    | SS
                    | ST
                    | TM
                    | UI
                    | UL
                    | US
            );
            let len = if short {
                self.u16_at(at + 6).map(|l| (u32::from(l), 8))
            } else {
                self.u32_at(at + 8).map(|l| (l, 12))
            };
            match len {
                Some((len, size)) => (vr, len, size),
                None => return Ok(None),
            }
        };
        self.pos = at + size;
        Ok(Some(Header {
            tag,
            vr,
            len,
            at: self.offset + at,
        }))
    }

    /// Checks that the defined length of `h` fits in what follows, and steps over the value
    /// as the parser does: it reads `len / size` numbers of a binary number VR, so the bytes
    /// of a length that is not a multiple of the size are left for the next header.
    fn value(&mut self, h: &Header) -> std::result::Result<&'a [u8], String> {
        self.check_fits(h)?;
        use VR::*;
        let size = match h.vr {
            US | OW | SS => 2,
            AT | FL | OF | SL | OL | UL => 4,
            FD | OD | SV | UV | OV => 8,
            _ => 1,
        };
        let len = h.len as usize / size * size;
        let end = (self.pos + len).min(self.data.len());
        let value = &self.data[self.pos..end];
        self.pos = end;
        Ok(value)
    }

    /// Walks a data set to its end.
    fn data_set(mut self) -> std::result::Result<(), String> {
        // The open containers, with the end of those of defined length.
        let mut open: Vec<(Container, Option<usize>)> = Vec::new();
        loop {
            while open
                .last()
                .is_some_and(|&(_, end)| end.is_some_and(|e| self.pos >= e))
            {
                open.pop();
            }
            let Some(h) = self.header()? else {
                return Ok(());
            };
            let end_of =
                |pos: usize| (h.len != UNDEFINED).then(|| pos.saturating_add(h.len as usize));
            match h.tag {
                ITEM if open.last().is_some_and(|&(c, _)| c == Container::Fragments) => {
                    self.value(&h)?;
                }
                ITEM => {
                    if h.len != UNDEFINED {
                        self.check_fits(&h)?;
                    }
                    open.push((Container::Item, end_of(self.pos)));
                }
                ITEM_END => {
                    if open.last().is_some_and(|&(c, _)| c == Container::Item) {
                        open.pop();
                    }
                }
                SEQUENCE_END => {
                    // Closes the innermost sequence of undefined length (and its open item).
                    while let Some((c, end)) = open.pop() {
                        if c != Container::Item && end.is_none() {
                            break;
                        }
                    }
                }
                _ if h.len == UNDEFINED => {
                    let c = if h.tag == PIXEL_DATA {
                        Container::Fragments
                    } else {
                        Container::Sequence
                    };
                    open.push((c, None));
                }
                _ if h.vr == VR::SQ => {
                    self.check_fits(&h)?;
                    open.push((Container::Sequence, end_of(self.pos)));
                }
                _ => {
                    self.value(&h)?;
                }
            }
            if open.len() > MAX_DEPTH {
                return Err(format!(
                    "sequences nested more than {MAX_DEPTH} deep (at byte {})",
                    h.at
                ));
            }
        }
    }

    /// Checks that the defined length of `h` fits in what follows its header (an odd length
    /// may be read as the next even one).
    fn check_fits(&self, h: &Header) -> std::result::Result<(), String> {
        let left = self.data.len() - self.pos;
        if h.len as usize > left + 1 {
            return Err(format!(
                "element ({:04X},{:04X}) at byte {} declares {} bytes, but only {left} bytes \
                 follow",
                h.tag.0, h.tag.1, h.at, h.len
            ));
        }
        Ok(())
    }
}
