// The login page: posts the token, which sets the px_token cookie, then opens the app. A token in
// the address's fragment (the QR code's link) logs in at once; the fragment never reaches a server.
'use strict';

async function logIn(token) {
  const message = document.getElementById('login-message');
  message.textContent = 'Logging in…';
  const reply = await fetch('/api/login', {
    method: 'POST',
    headers: {'Content-Type': 'application/json'},
    body: JSON.stringify({token}),
  });
  if (reply.ok) {
    history.replaceState(null, '', '/login.html');
    location.href = '/';
  } else {
    const body = await reply.json().catch(() => ({}));
    message.textContent = body.error || `Refused (${reply.status})`;
  }
}

document.getElementById('login-form').addEventListener('submit', (event) => {
  event.preventDefault();
  logIn(document.getElementById('token').value.trim());
});

const fromLink = new URLSearchParams(location.hash.slice(1)).get('token');
if (fromLink) logIn(fromLink);
