// Choosing among the series and stacks of DICOM files opened in the page (a
// dropped folder, or a DICOMweb series rebuilt as files by dicomweb.js): a
// multi-frame object may hold several stacks (Stack IDs, or orientations),
// a folder several series. The module reads the largest (as the CLI does)
// and says what else there was (tessera_dicom_stacks_json, listed by the
// series code the CLI's `tessera info` lists with); a small list then names
// each with its slices, and choosing one opens the same files again with
// that selection (tessera_dicom_select: "UID" or "UID:stack", the CLI's
// --series). Nothing shows for files of one series and one stack.

export function attachStacks({ module, reopen }) {
  const box = document.createElement('div');
  box.id = 'dicom-stacks';
  box.className = 'row';
  box.hidden = true;
  box.innerHTML = `<label><span class="note dicom-stacks-note"></span>
    <select class="dicom-stacks-select" aria-label="The DICOM series or stack shown"></select></label>`;
  const errorBox = document.getElementById('error');
  errorBox.parentNode.insertBefore(box, errorBox.nextSibling);
  const select = box.querySelector('select');
  const note = box.querySelector('.dicom-stacks-note');
  let held = null;  // the files opened, to open again with another choice
  let last = { read: '', series: [] };

  select.addEventListener('change', () => {
    if (held) reopen(held, select.value);
  });

  return {
    // The selection for the next open ("" the default).
    select(selector) {
      module.ccall('tessera_dicom_select', null, ['string'], [selector || '']);
    },
    // After an open of `name` succeeded: what the module found, and the
    // list when there is a choice. `entries` are kept only then. (A file
    // the DICOM reader did not read, a time series, leaves no list.)
    opened(entries, name) {
      last = JSON.parse(module.ccall('tessera_dicom_stacks_json', 'string', [], []));
      if (last.name !== name) last = { name, read: '', series: [] };
      const several = last.series.length > 1;
      held = several ? entries : null;
      box.hidden = !several;
      if (several) {
        const stacks = new Set(last.series.map((s) => s.series_instance_uid)).size === 1;
        note.textContent = `${last.series.length} ${stacks ? 'stacks in this series' : 'series and stacks in these files'}; shown:`;
        select.replaceChildren(...last.series.map((s) => {
          const o = document.createElement('option');
          o.value = s.select;
          o.textContent = `${s.stack ? `stack ${s.stack}` : s.select}: ${s.slices} slices${s.description ? `, ${s.description}` : ''}`;
          o.selected = s.select === last.read;
          return o;
        }));
      }
      return last;
    },
    // For tests: what the last open found ({read, series: [{select, …}]}).
    state: () => last,
  };
}
